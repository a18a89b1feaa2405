"""Session set-up: the test device switch (see ``helpers_device.py``) and run files shared by several test files."""

import pytest
from helpers_device import configure_warp

configure_warp()


@pytest.fixture(scope="session")
def running_pst(tmp_path_factory) -> str:
    """A 2D PST run file whose crack runs to the far end (``helpers_scenes.RUNNING_PST``), on the CPU."""
    from helpers_scenes import RUNNING_PST

    import mpm_warp as mw

    out = str(tmp_path_factory.mktemp("running_pst") / "pst.h5")
    mw.run("pst_demo", out, "cpu", RUNNING_PST)
    return out


@pytest.fixture(scope="session")
def sloped_pst(tmp_path_factory) -> str:
    """The same column on a 30 degree slope (``helpers_scenes.RUNNING_PST_SLOPE``), on the CPU."""
    from helpers_scenes import RUNNING_PST_SLOPE

    import mpm_warp as mw

    out = str(tmp_path_factory.mktemp("sloped_pst") / "pst.h5")
    mw.run("pst_demo", out, "cpu", RUNNING_PST_SLOPE)
    return out
