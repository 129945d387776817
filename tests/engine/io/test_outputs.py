"""The result folder's files: edited.exr is the panorama plus the difference, the pixels the
removal changed stored to the difference's precision and the others exactly as photographed."""
from __future__ import annotations

import numpy as np

from addon.io import exr
from addon.io.outputs import write_outputs
from addon.radiance import STORED_MANTISSA_BITS
from addon.removal.sequence import RemovalResult


def test_edited_keeps_unchanged_pixels_exactly_and_rounds_the_changed_ones(tmp_path):
    rng = np.random.default_rng(5)
    hdri = (rng.random((9, 14, 3)) * np.array([1.0, 50.0, 3000.0])).astype(np.float32)
    difference = (rng.random(hdri.shape) * 0.3 - 0.1).astype(np.float32) * hdri
    difference[2:5, 3:9] = 0.0  # an emitter, say: left as it is
    result = RemovalResult(difference=difference, hidden_mask=np.zeros(hdri.shape[:2], bool), report={},
                           hdri=hdri)
    write_outputs(str(tmp_path / "out"), result, {"seconds": {}})
    edited = exr.read_exr(tmp_path / "out" / "edited.exr")
    exact = hdri + difference
    unchanged = difference == 0
    np.testing.assert_array_equal(edited[unchanged], hdri[unchanged])
    relative = np.abs(edited - exact) / np.abs(exact)
    assert relative[~unchanged].max() <= 2.0 ** -(STORED_MANTISSA_BITS + 1)
    # Rounded, not cut short: some values moved, and the low mantissa bits are zero.
    assert (edited[~unchanged] != exact[~unchanged]).any()
    low_bits = edited[~unchanged].view(np.uint32) & np.uint32((1 << (23 - STORED_MANTISSA_BITS)) - 1)
    assert not low_bits.any()
