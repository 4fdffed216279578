"""mmrtm-web: MM-RTM path tracing in a browser, on trame-slicer (Documentation/web.md)."""
