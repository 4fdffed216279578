"""mmrtm-web: a study path traced by MM-RTM in a browser, on trame-slicer.

    mmrtm-web [VOLUME_OR_DICOM_FOLDER] [--data-root DIR] [--host 127.0.0.1] [--port 8080]

Serves a page with Slicer's layouts (the 3D view path traced by our method,
the axial, coronal and sagittal slices beside it), Slicer's Volume
Rendering presets, and the studies of the data root to open. The 3D view refines in the background (the display
node's AsynchronousRefinement), so the server answers the browser between
sample passes. Documentation/web.md says what it does and does not do yet.
"""
import argparse
import ipaddress
import os
import sys

METHOD = "vtkMRMLMultiMaterialVolumeRenderingDisplayNode"
# The methods the page offers: ours, and Slicer's CPU ray cast to compare.
METHODS = {"Path tracing (MM-RTM)": METHOD, "Slicer's CPU ray cast": "vtkMRMLCPURayCastVolumeRenderingDisplayNode"}
DEFAULT_PRESET = "CT-Bone"


def parse_arguments(argv):
    parser = argparse.ArgumentParser(prog="mmrtm-web", description=__doc__.split("\n\n")[0])
    parser.add_argument("volume", nargs="?", help="a volume file (NRRD, NIfTI, MetaImage) or a DICOM folder")
    parser.add_argument("--data-root", help="the folder the page may open studies from (default: the study's "
                        "folder); paths that lead outside it are refused")
    parser.add_argument("--host", default="127.0.0.1", help="address to serve on (default: loopback only)")
    parser.add_argument("--port", type=int, default=8080, help="port (default 8080; 0: any free port)")
    parser.add_argument("--preset", default=DEFAULT_PRESET, help="Volume Rendering preset (default CT-Bone)")
    parser.add_argument("--maximum-samples", type=int, default=64, help="samples per pixel to refine to (default 64)")
    return parser.parse_args(argv)


def volume_files(path):
    """The files Slicer's volumes reader gets for `path`: a DICOM folder's
    files (sorted), or the file itself. Raises ValueError naming the problem."""
    if os.path.isdir(path):
        files = sorted(os.path.join(path, f) for f in os.listdir(path) if os.path.isfile(os.path.join(path, f)))
        if not files:
            raise ValueError("the folder holds no files")
        return files
    if not os.path.isfile(path):
        raise ValueError("no such file or folder")
    return [path]


def is_loopback(host):
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


class WebViewer:
    """The trame server, the Slicer core behind it, and the page."""

    def __init__(self, volume_path, data_root, preset=DEFAULT_PRESET, maximum_samples=64, server=None):
        from trame.app import get_server
        from trame.widgets import vuetify3
        from trame_client.widgets import html
        from trame_client.widgets.html import Div
        from trame_slicer.core import LayoutManager, SlicerApp
        from trame_slicer.rca_view import register_rca_factories
        from trame_vuetify.ui.vuetify3 import SinglePageLayout
        from slicer import vtkSlicerMultiMaterialVolumeRenderingLogic

        self.server = get_server(server, client_type="vue3")
        self.slicer = SlicerApp()
        # Our method in Volume Rendering's list, as the Slicer module does.
        self.slicer.register_module_logic(vtkSlicerMultiMaterialVolumeRenderingLogic(),
                                          logic_name="MultiMaterialVolumeRendering")
        self.volume_rendering = self.slicer.volume_rendering
        self.volume_rendering_logic = self.slicer.app_logic.GetModuleLogic("VolumeRendering")
        self.volume_rendering_logic.SetDefaultRenderingMethod(METHOD)
        register_rca_factories(self.slicer.view_manager, self.server)
        self.layouts = LayoutManager(self.slicer.scene, self.slicer.view_manager, self.server)
        self.layouts.register_layout_dict(LayoutManager.default_grid_configuration())
        self.maximum_samples = maximum_samples
        self.data_root = data_root
        self.volume = None

        state = self.server.state
        state.trame__title = "mmrtm-web"
        state.presets = self.volume_rendering.preset_names()
        state.preset = preset if preset in state.presets else (state.presets[0] if state.presets else "")
        state.change("preset")(self.on_preset)
        state.methods = list(METHODS)
        state.method = state.methods[0]
        state.change("method")(self.on_method)
        state.studies = data_root.studies()
        state.study = ""
        state.shown = ""  # the study shown, as the data root names it
        state.message = ""
        self.server.controller.open_study = self.on_open_study

        with SinglePageLayout(self.server) as self.ui:
            self.ui.title.set_text("mmrtm-web: path tracing (MM-RTM)")
            with self.ui.toolbar:
                vuetify3.VSpacer()
                html.Span("{{ shown }}", classes="shown-study text-body-2 mr-4")
                vuetify3.VCombobox(v_model=("study",), items=("studies",), label="Study (in the data root)",
                                   density="compact", hide_details=True, style="max-width: 320px",
                                   classes="study-path")
                vuetify3.VBtn("Open", click=self.server.controller.open_study, classes="open-study")
                vuetify3.VSelect(v_model=("preset",), items=("presets",), label="Preset", density="compact",
                                 hide_details=True, style="max-width: 240px", classes="preset-select")
                vuetify3.VSelect(v_model=("method",), items=("methods",), label="Rendering", density="compact",
                                 hide_details=True, style="max-width: 240px", classes="method-select")
            with self.ui.content:
                vuetify3.VAlert(v_if=("message",), text=("message",), type="error", density="compact",
                                closable=True, classes="study-message")
                with Div(classes="fill-height d-flex flex-row flex-grow-1"):
                    self.layouts.initialize_layout_grid(self.ui)
        self.layouts.set_layout("3D Primary")
        path = data_root.resolve(volume_path)
        try:
            self.volume = self.load(path)
        except ValueError as e:
            raise ValueError("%s: %s" % (path, e)) from e
        state.shown = os.path.relpath(path, data_root.folder)

    def load(self, path):
        """Loads the study, shows it path traced and in the slice views, in
        place of the one shown before. Raises ValueError saying why when
        Slicer's reader cannot read it (the study shown stays); the caller
        names the path, as the page knows it."""
        files = volume_files(path)
        try:
            nodes = self.slicer.io_manager.load_volumes(files)
        except Exception as e:  # Slicer's reader raises what it likes on damaged input
            raise ValueError("Slicer's volumes reader could not read it (%s)" % type(e).__name__) from e
        if not nodes or nodes[0] is None:
            raise ValueError("Slicer's volumes reader could not read it (damaged, or not a volume)")
        volume = nodes[0]
        if self.volume is not None:
            shown = self.volume_rendering.get_vr_display_node(self.volume)
            if shown is not None:
                self.slicer.scene.RemoveNode(shown)
            self.slicer.scene.RemoveNode(self.volume)
        self.slicer.display_manager.show_volume(volume, vr_preset=self.server.state.preset, do_reset_views=True)
        self.configure(self.volume_rendering.get_vr_display_node(volume))
        return volume

    def configure(self, display):
        """Our settings on a display node of the chosen method (Volume
        Rendering makes a new node at each method change)."""
        wanted = METHODS[self.server.state.method]
        if display is None or not display.IsA(wanted):
            raise RuntimeError("Volume Rendering made a %s, not a %s"
                               % (display.GetClassName() if display else "no node", wanted))
        if display.IsA(METHOD):
            display.SetAsynchronousRefinement(True)
            display.SetMaximumSamples(self.maximum_samples)

    def on_open_study(self):
        """The page's Open: the study typed or chosen, if the data root holds
        it; otherwise a message in the page (the server goes on)."""
        state = self.server.state
        try:
            path = self.data_root.resolve(state.study)
        except ValueError as e:
            state.message = str(e)
            return
        try:
            self.volume = self.load(path)
            state.message = ""
            state.shown = state.study
        except ValueError as e:
            state.message = "'%s': %s" % (state.study, e)

    def on_method(self, method, **_):
        if method not in METHODS:
            return
        self.volume_rendering_logic.SetDefaultRenderingMethod(METHODS[method])
        if self.volume is not None:
            self.volume_rendering_logic.ChangeVolumeRenderingMethod(METHODS[method])
            self.configure(self.volume_rendering.get_vr_display_node(self.volume))

    def on_preset(self, preset, **_):
        if getattr(self, "volume", None) is not None and preset:
            self.volume_rendering.apply_preset(self.volume_rendering.get_vr_display_node(self.volume), preset)


def main(argv=None):
    args = parse_arguments(sys.argv[1:] if argv is None else argv)
    # Without a display the PyPI VTK renders through EGL; say so up front
    # instead of letting it warn.
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    try:
        import trame_slicer  # noqa: F401
        import mmrtm_slicer  # noqa: F401
    except ImportError as e:
        sys.exit("mmrtm-web: %s: it needs trame-slicer and the mmrtm wheel built with its Slicer classes "
                 "(pip install mmrtm[web]; Documentation/web.md)" % e)
    if args.volume is None:
        sys.exit("mmrtm-web: name a volume file or a DICOM folder (mmrtm-web --help)")
    from .data_root import DataRoot
    try:
        root = DataRoot(args.data_root or os.path.dirname(os.path.abspath(args.volume.rstrip("/"))))
    except ValueError as e:
        sys.exit("mmrtm-web: error: %s" % e)
    if not is_loopback(args.host):
        print("mmrtm-web: warning: serving on %s, beyond this machine, with no authentication: put it behind a "
              "reverse proxy that authenticates (Documentation/web.md)" % args.host, file=sys.stderr)
    try:
        viewer = WebViewer(os.path.abspath(args.volume), root, preset=args.preset,
                           maximum_samples=args.maximum_samples)
    except ValueError as e:
        sys.exit("mmrtm-web: error: %s" % e)
    viewer.server.start(host=args.host, port=args.port, open_browser=False)


if __name__ == "__main__":
    main()
