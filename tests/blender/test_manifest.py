"""The extension manifest validates, and the built zip holds the add-on and its wheels only."""
from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# Blender's Python versions: 3.11 for 4.2 LTS up to 5.0, 3.13 from 5.1.
BLENDER_PYTHONS = ("cp311", "cp313")
# Parts of the wheel platform tag that each Blender platform needs.
WHEEL_PLATFORMS = {
    "linux-x64": ("manylinux", "x86_64"),
    "windows-x64": ("win_amd64",),
    "macos-arm64": ("macosx", "arm64"),
    "macos-x64": ("macosx", "x86_64"),
}


def _load_build_script():
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "scripts" / "build_extension.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build_extension = _load_build_script()


@pytest.fixture(scope="module")
def built_zip(tmp_path_factory) -> Path:
    (path,) = build_extension.build(tmp_path_factory.mktemp("dist"))
    return path


def test_manifest_validates():
    # With Blender's list of valid tags, as the build does.
    try:
        build_extension.validate()
    except SystemExit as failure:
        pytest.fail(str(failure))


def test_manifest_fields():
    manifest = build_extension.manifest()
    assert manifest["id"] == "diminished_reality"
    assert manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert set(manifest["permissions"]) == {"files"}


def test_every_platform_has_a_wheel_for_every_blender_python():
    manifest = build_extension.manifest()
    wheels = [Path(w).name for w in manifest["wheels"]]
    assert len({w.split("-")[1] for w in wheels}) == 1, "all wheels must be one pinned version"
    for platform in manifest["platforms"]:
        for python in BLENDER_PYTHONS:
            assert any(
                f"-{python}-" in w and all(part in w.split("-")[-1] for part in WHEEL_PLATFORMS[platform])
                for w in wheels
            ), (platform, python)


def test_zip_holds_the_add_on_and_no_development_files(built_zip):
    names = set(zipfile.ZipFile(built_zip).namelist())
    for required in ("__init__.py", "blender_manifest.toml", "addon/geometry/latlong.py",
                     "operators/__init__.py", "operators/support/world_layer.py", "panels/__init__.py"):
        assert required in names
    wheels = {Path(w).name for w in build_extension.manifest()["wheels"]}
    assert {Path(n).name for n in names if n.endswith(".whl")} == wheels
    for name in names:
        top = name.split("/")[0]
        assert top not in {"tests", "scenes", "scripts", "benchmarks", "dist", "out", "dev"}, name
        assert not top.startswith("."), name
        assert "__pycache__" not in name and not name.endswith(".pyc"), name


def test_zip_validates(built_zip):
    result = subprocess.run(
        [sys.executable, str(build_extension.find_blender_ext()), "validate", str(built_zip)],
        capture_output=True, text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr


INSTALL_SCRIPT = """
import os, sys
from pathlib import Path
import bpy
result = bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
assert result == {'FINISHED'}, result
assert "bl_ext.user_default.diminished_reality" in bpy.context.preferences.addons
assert hasattr(bpy.types, "DIMRED_OT_remove")
tag = "cpython-{}{}".format(*sys.version_info[:2])
site = Path(os.environ["BLENDER_USER_RESOURCES"], "extensions", ".local")
assert list(site.rglob(f"OpenEXR.{tag}-*")), f"no {tag} OpenEXR under {site}"
print("installed")
"""


def test_zip_installs_and_enables_on_this_blender(built_zip, tmp_path):
    # A fresh process: Blender reads BLENDER_USER_RESOURCES once, when bpy is first imported.
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "user"))
    result = subprocess.run(
        [sys.executable, "-c", INSTALL_SCRIPT, str(built_zip)], capture_output=True, text=True, env=env
    )
    assert result.returncode == 0 and "installed" in result.stdout, result.stdout + result.stderr
