"""Small snow scenes for the tests: the ready scenes shrunk to a few thousand particles.

``TINY_PST``: ``pst_demo`` as a 0.6 m column with a 15 cm slab on a 1 cm grid (3 cells across a 3 cm
weak layer, the minimum), settled by 0.04 s, the saw cutting at 1 m/s from then on up to 15 cm; about
3.6k particles. Tests add their own ``time.end`` and output overrides.

``RUNNING_PST``: ``TINY_PST`` with a 30 cm slab on a layer of field-low toughness (w_f = 0.1 J/m^2), a frame
every 10 ms to 0.23 s: the crack runs away from the saw to the far end (float32, 8.6k particles, 23 frames;
about 10 s on one CPU core). ``RUNNING_PST_SLOPE`` is the same column on a 30 degree slope (its crack does not
run by 0.23 s: the damage front stays at the saw).
"""

TINY_PST = ["scene.length=0.6", "scene.slab_thickness=0.15", "scene.dx=0.01", "scene.weak_layer_thickness=0.03",
            "scene.substratum_thickness=0.03", "scene.margin=0.03", "scene.saw.cut_length=0.15",
            "scene.settle.gravity_ramp=0.02", "scene.settle.duration=0.04", "time.frame_interval=0.005"]

RUNNING_PST = TINY_PST + ["scene.slab_thickness=0.3", "scene.weak_layer.w_f=0.1", "scene.saw.cut_length=0.3",
                          "time.end=0.23", "time.frame_interval=0.01"]
RUNNING_PST_SLOPE = RUNNING_PST + ["scene.slope_angle=30"]


def assert_same_series(a: dict, b: dict) -> None:
    """Two monitors' frame series are the same, bit for bit (NaN where the other has NaN: touchdown before the
    crack runs)."""
    import numpy as np

    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(np.asarray(a[k], dtype=float), np.asarray(b[k], dtype=float), err_msg=k)
