"""Build the extension zip: fetch the manifest's wheels, validate the manifest, build into dist/.

The wheels the manifest lists are not in git; any that are missing are downloaded from PyPI
into wheels/ (present ones are kept, so a build works offline once they are there). Validation
and the build use `blender_ext.py`, the extension tool that the installed `bpy` package ships,
run under plain Python with Blender's own list of valid tags.

    python scripts/build_extension.py [--out-dir DIR] [--split-platforms]

prints the path of each zip it wrote, one per line, on stdout.
"""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "blender_manifest.toml"


def find_blender_ext() -> Path:
    """The `blender_ext.py` of the bpy package importable by this interpreter (not imported)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("build_extension: the bpy package is not installed for " + sys.executable)
    package = Path(next(iter(spec.submodule_search_locations)))
    found = sorted(package.glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not found:
        raise SystemExit(f"build_extension: no blender_ext.py under {package}")
    return found[-1]


def valid_tags_file(blender_ext: Path) -> Path | None:
    """Blender's list of valid extension tags, next to the `blender_ext.py` it belongs to."""
    tags = blender_ext.parents[3] / "modules" / "_bpy_internal" / "extensions" / "tags.py"
    return tags if tags.is_file() else None


def manifest() -> dict:
    """The parsed blender_manifest.toml."""
    with MANIFEST.open("rb") as fh:
        return tomllib.load(fh)


def _pip_download_args(wheel: Path) -> list[str]:
    """pip arguments that fetch exactly this wheel file: name-version-python-abi-platform.whl."""
    name, version, python_tag, abi_tag, platform_tag = wheel.stem.split("-")
    digits = python_tag.removeprefix("cp")
    return [
        "--no-deps", "--only-binary=:all:", "--implementation", "cp",
        "--python-version", f"{digits[0]}.{digits[1:]}", "--abi", abi_tag,
        "--platform", platform_tag, f"{name}=={version}",
    ]


def fetch_wheels(data: dict) -> None:
    """Download each wheel the manifest lists that is not in place yet."""
    for entry in data.get("wheels", []):
        wheel = (ROOT / entry).resolve()
        if wheel.is_file():
            continue
        wheel.parent.mkdir(parents=True, exist_ok=True)
        print(f"build_extension: downloading {wheel.name}", file=sys.stderr)
        subprocess.run(
            [sys.executable, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
             "--dest", str(wheel.parent), *_pip_download_args(wheel)],
            check=True,
        )
        if not wheel.is_file():
            # pip may pick another compatible build (say an older manylinux tag) than the one named.
            raise SystemExit(f"build_extension: PyPI did not provide {wheel.name}; fix the manifest's wheels")


def _run_blender_ext(blender_ext: Path, command: str, *args: str) -> None:
    tags = valid_tags_file(blender_ext)
    tag_args = [f"--valid-tags={tags}"] if tags else []
    result = subprocess.run(
        [sys.executable, str(blender_ext), command, *args, *tag_args],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    if result.returncode != 0:
        raise SystemExit(f"build_extension: blender_ext.py {command} failed:\n{result.stdout.strip()}")
    print(result.stdout.strip(), file=sys.stderr)


def validate(*, blender_ext: Path | None = None) -> None:
    """Validate the source tree's manifest; SystemExit with blender_ext.py's message if invalid."""
    _run_blender_ext(blender_ext or find_blender_ext(), "validate", str(ROOT))


def build(out_dir: Path, *, split_platforms: bool = False, blender_ext: Path | None = None) -> list[Path]:
    """Fetch wheels, validate and build; returns the zip(s) written into out_dir."""
    blender_ext = blender_ext or find_blender_ext()
    data = manifest()
    fetch_wheels(data)
    validate(blender_ext=blender_ext)
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    split = ["--split-platforms"] if split_platforms else []
    _run_blender_ext(blender_ext, "build", "--source-dir", str(ROOT), "--output-dir", str(out_dir), *split)
    stem = f"{data['id']}-{data['version']}"
    if split_platforms:
        zips = [out_dir / f"{stem}-{platform.replace('-', '_')}.zip" for platform in data["platforms"]]
    else:
        zips = [out_dir / f"{stem}.zip"]
    missing = [str(z) for z in zips if not z.is_file()]
    if missing:
        raise SystemExit(f"build_extension: blender_ext.py did not write {', '.join(missing)}")
    return zips


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=ROOT / "dist", help="where the zip goes (default dist/)")
    parser.add_argument("--split-platforms", action="store_true",
                        help="one smaller zip per platform, each with only that platform's wheels")
    args = parser.parse_args(argv)
    for path in build(args.out_dir, split_platforms=args.split_platforms):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
