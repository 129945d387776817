"""`dimred batch`: many removals, relocations and alignments, each in its own process, resumable.

The layers: `jobs` reads and checks the jobs file, `fingerprint` hashes what a job's result
depends on, `execute` runs one job in a child process and installs its folder, `local` and
`cluster` run many (local processes under a memory budget, or Dask's scheduler), `summary`
writes the batch's tables, `progress` draws the terminal's bar and `batch` ties them together.
None of them imports bpy: the jobs run `python -m addon.cli` or `blender -b ... -c dimred`.
"""
