# Entry point of the MM-RTM Slicer classes in the "slicer" meta-package of
# slicer-core. They need slicer-layer-dm too (pip install mmrtm[slicer]);
# without it `import slicer` must still work, so a failed import only warns.
try:
    from mmrtm_slicer import *  # noqa: F401,F403
except ImportError as error:
    import warnings

    warnings.warn("the MM-RTM Slicer classes are not available (%s); they need slicer-core==5.11.0.6 and "
                  "slicer-layer-dm==2.0.0" % error)
