# Entry point of the MM-RTM Slicer classes in the "slicer" meta-package.
from mmrtm_slicer import *  # noqa: F401,F403
