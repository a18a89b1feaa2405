"""Session set-up: the test device switch (see ``helpers_device.py``)."""

from helpers_device import configure_warp

configure_warp()
