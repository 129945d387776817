"""Cached ground-truth render pairs: `render_pair(spec)` renders once, then reuses the files.

Each pair lives in `.cache/groundtruth/<spec.key()>/` at the repository root (git-ignored):
`input.exr`, `truth.exr`, `mask.npy`, `scene.blend`, `spec.json`, `times.json`. The render runs
in a subprocess (`scenes.render_job`) and is moved into the cache only when complete, so an
interrupted or failed render never leaves a partial entry behind. A pair whose truth another
cached pair already holds (a relocation's: the same room without the object) copies it instead
of rendering it again.
"""
from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .images import read_exr
from .spec import SceneSpec

REPO = Path(__file__).resolve().parents[1]
CACHE_ROOT = REPO / ".cache" / "groundtruth"
FILES = {"input": "input.exr", "truth": "truth.exr", "mask": "mask.npy",
         "blend": "scene.blend", "spec": "spec.json", "times": "times.json"}


def pair_paths(spec: SceneSpec, cache_root: Path = CACHE_ROOT) -> dict[str, Path]:
    """Where the files of `spec`'s pair are (or will be), by the keys of `FILES`."""
    folder = cache_root / spec.key()
    return {k: folder / name for k, name in FILES.items()}


def render_pair(spec: SceneSpec, cache_root: Path = CACHE_ROOT,
                timeout: float | None = None) -> dict[str, Path]:
    """Render `spec` with and without its removed object unless cached; return the file paths.

    Raises `RuntimeError` with the end of the job's output when the render fails.
    """
    paths = pair_paths(spec, cache_root)
    if all(p.exists() for p in paths.values()):
        return paths
    cache_root.mkdir(parents=True, exist_ok=True)
    # One Cycles render at a time across processes: two would share the cores and both crawl.
    with open(cache_root / ".render.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if all(p.exists() for p in paths.values()):
            return paths
        _render_into_cache(spec, paths, cache_root, timeout)
    return paths


def _render_into_cache(spec: SceneSpec, paths: dict[str, Path], cache_root: Path,
                       timeout: float | None) -> None:
    work = Path(tempfile.mkdtemp(prefix=f"{spec.key()}.", suffix=".tmp", dir=cache_root))
    try:
        (work / FILES["spec"]).write_text(spec.to_json())
        truth = _cached_truth(spec, cache_root)
        if truth is not None:
            shutil.copyfile(truth, work / FILES["truth"])
        # Scenes with a photographed floor, windows or chairs build with scenes.build_extended.
        module = "scenes.build_extended" if spec.extended() else "scenes.render_job"
        _job(["pair", str(work)], f"render of {spec.name!r}", timeout, module)
        folder = paths["input"].parent
        try:
            work.rename(folder)
        except OSError:
            # Another process finished the same key first; its files are equally good.
            if not all(p.exists() for p in paths.values()):
                raise
    finally:
        if work.exists():
            shutil.rmtree(work)


def _cached_truth(spec: SceneSpec, cache_root: Path) -> Path | None:
    """A cached pair's truth that is `spec`'s too (the same `truth_key`), else None: a
    relocation's truth shares the room without the object with the pair it moves."""
    want = spec.truth_key()
    for folder in cache_root.iterdir():
        paths = {k: folder / name for k, name in FILES.items()}
        if not all(p.exists() for p in paths.values()):
            continue
        try:
            cached = SceneSpec.from_json(paths["spec"].read_text())
        except (ValueError, TypeError, KeyError):  # a spec of older fields: a stale folder
            continue
        # The folder's name is its spec's key under the present render code, or it is stale.
        if folder.name == cached.key() and cached.truth_key() == want:
            return paths["truth"]
    return None


def render_world(blend: str | Path, out_exr: str | Path,
                 timeout: float | None = None) -> np.ndarray:
    """Render the world of a saved scene from its probe centre with the standard panoramic
    camera (see `scenes.render_job`), write `out_exr` and return its pixels (not cached)."""
    _job(["world", str(Path(blend).resolve()), str(Path(out_exr).resolve())],
         f"world render of {blend}", timeout)
    return read_exr(out_exr)


def _job(args: list[str], what: str, timeout: float | None, module: str = "scenes.render_job") -> None:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])]))
    proc = subprocess.run([sys.executable, "-m", module, *args], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        tail = (proc.stdout + proc.stderr)[-3000:]
        raise RuntimeError(f"{what} failed (exit {proc.returncode}):\n{tail}")


def load_pair(spec: SceneSpec,
              cache_root: Path = CACHE_ROOT) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(input, truth, mask) of `spec`, rendering first if needed: (H, W, 3) float32 top row
    first, and the (H, W) bool mask of the removed object."""
    paths = render_pair(spec, cache_root)
    return read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
