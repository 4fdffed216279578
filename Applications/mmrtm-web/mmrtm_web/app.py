"""mmrtm-web: a study path traced by MM-RTM in a browser, on trame-slicer.

    mmrtm-web [VOLUME_OR_DICOM_FOLDER] [--data-root DIR] [--host 127.0.0.1] [--port 8080]
              [--token-file FILE] [--certfile CERT --keyfile KEY]

Serves a page with Slicer's layouts (the 3D view path traced by our method,
the axial, coronal and sagittal slices beside it), Slicer's Volume
Rendering presets, the shift, segmentations shown as materials, and the
studies of the data root to open or a file to upload. The 3D view refines
in the background (the display node's AsynchronousRefinement) and is
streamed one frame per sample pass (streaming.py). Documentation/web.md
says what it does and does not do yet.

Only the holder of the server's access key gets anything from it: the
address printed at start carries the key (access.py); TLS by
--certfile/--keyfile, required beyond this machine unless --insecure.
"""
import argparse
import ipaddress
import os
import socket
import sys

from . import transfer_functions
from .access import SHORTEST_TOKEN, TOKEN_ENVIRONMENT, AccessError, AccessKey, chosen_token, tls_context
from .clients import ClientPresence
from .studies import DEFAULT_STUDY, StudyLoader
from .transfer_functions import hex_colour

METHOD = "vtkMRMLMultiMaterialVolumeRenderingDisplayNode"
# The methods the page offers: ours, and Slicer's CPU ray cast to compare.
METHODS = {"Path tracing (MM-RTM)": METHOD, "Slicer's CPU ray cast": "vtkMRMLCPURayCastVolumeRenderingDisplayNode"}
DEFAULT_PRESET = "CT-Bone"
# The materials menu's first entry: the volume property translated, as
# Volume Rendering's preset and the editor make it.
VOLUME_PROPERTY_MATERIALS = "From the volume property"
# What the 3D view shows (the display node's DenoisingMode), by the page's names.
DISPLAYS = {"Denoised while closer": 1, "Denoised": 2, "Unbiased": 0}
DEFAULT_DISPLAY = "Denoised while closer"


def material_presets():
    """The project's MM-RTM material presets (ct-bone, mri, ...), which
    replace the volume property's translation."""
    from mmrtm import vtkMultiMaterialProperty

    folder = vtkMultiMaterialProperty.GetPresetDirectory()
    return sorted(f[:-len(".json")] for f in os.listdir(folder) if f.endswith(".json")) if os.path.isdir(folder) else []


def parse_arguments(argv):
    parser = argparse.ArgumentParser(prog="mmrtm-web", description=__doc__.split("\n\n")[0])
    parser.add_argument("volume", nargs="?", default=DEFAULT_STUDY,
                        help="a volume file (NRRD, NIfTI, MetaImage, InVesalius) or a DICOM folder "
                        "(default: the head CT of Debian's invesalius-examples)")
    parser.add_argument("--data-root", help="the folder the page may open studies from (default: the study's "
                        "folder); paths that lead outside it are refused")
    parser.add_argument("--host", default="127.0.0.1", help="address to serve on (default: loopback only; "
                        "any other needs --certfile or --insecure)")
    parser.add_argument("--port", type=int, default=8080, help="port (default 8080; 0: any free port)")
    parser.add_argument("--preset", default=DEFAULT_PRESET, help="Volume Rendering preset (default CT-Bone)")
    parser.add_argument("--maximum-samples", type=int, default=64, help="samples per pixel to refine to (default 64)")
    parser.add_argument("--upload-limit-mb", type=float, default=512,
                        help="largest file the page may upload, in MiB (default 512; 0: no uploads)")
    parser.add_argument("--streaming", choices=("progressive", "trame-rca"), default="progressive",
                        help="how the 3D view is streamed: one frame per sample pass (default), or trame-rca's "
                        "own scheduler, to compare (Testing/Benchmarks/bench_web.py)")
    access = parser.add_argument_group("access", "who may use the server (Documentation/web.md, Security)")
    access.add_argument("--token-file", help="the access key in the file's first line (at least %d characters; "
                        "default: %s, else a random key made at start and printed in the address to open)"
                        % (SHORTEST_TOKEN, TOKEN_ENVIRONMENT))
    access.add_argument("--no-token", action="store_true",
                        help="serve without an access key: anyone who can reach the port sees the studies "
                        "(loopback only)")
    access.add_argument("--certfile", help="serve over HTTPS with this PEM certificate (and its key, unless "
                        "--keyfile names another file)")
    access.add_argument("--keyfile", help="the certificate's private key (PEM)")
    access.add_argument("--insecure", action="store_true",
                        help="allow a --host beyond this machine without TLS (the key and the images cross the "
                        "network in the clear)")
    return parser.parse_args(argv)


def access_settings(args, environment=os.environ):
    """The key (None without one) and the TLS context (None without TLS) the
    arguments ask for, or a message for the user when they are unsafe or
    unusable."""
    if args.keyfile and not args.certfile:
        raise AccessError("--keyfile needs --certfile")
    context = tls_context(args.certfile, args.keyfile) if args.certfile else None
    if args.no_token:
        if args.token_file:
            raise AccessError("--no-token and --token-file contradict each other")
        if not is_loopback(args.host):
            raise AccessError("--no-token serves only on loopback (--host %s would let anyone who reaches the "
                              "port see the studies)" % args.host)
        return None, context
    if not is_loopback(args.host) and context is None and not args.insecure:
        raise AccessError("--host %s serves beyond this machine: give --certfile and --keyfile for TLS, or "
                          "--insecure to send the key and the images in the clear" % args.host)
    return chosen_token(args.token_file, environment), context


def address_to_open(host, port, token, tls):
    """The URL the user opens: this server with its key."""
    if host in ("0.0.0.0", "::", ""):
        host = socket.getfqdn()
    if ":" in host:
        host = "[%s]" % host
    return "%s://%s:%d/%s" % ("https" if tls else "http", host, port, "?token=" + token if token else "")


def is_loopback(host):
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


class WebViewer:
    """The trame server, the Slicer core behind it, and the page."""

    def __init__(self, volume_path, data_root, preset=DEFAULT_PRESET, maximum_samples=64, upload_limit_mb=512,
                 streaming="progressive", server=None):
        from trame.app import get_server
        from trame_slicer.core import LayoutManager, SlicerApp
        from slicer import vtkSlicerMultiMaterialVolumeRenderingLogic

        from .streaming import register_view_factories

        self.server = get_server(server, client_type="vue3")
        self.slicer = SlicerApp()
        # Our method in Volume Rendering's list, as the Slicer module does.
        self.slicer.register_module_logic(vtkSlicerMultiMaterialVolumeRenderingLogic(),
                                          logic_name="MultiMaterialVolumeRendering")
        self.volume_rendering = self.slicer.volume_rendering
        self.volume_rendering_logic = self.slicer.app_logic.GetModuleLogic("VolumeRendering")
        self.volume_rendering_logic.SetDefaultRenderingMethod(METHOD)
        self.presence = ClientPresence(self.server)
        if streaming == "progressive":
            register_view_factories(self.slicer.view_manager, self.server, self.presence, self.on_frame)
        else:
            from trame_slicer.rca_view import register_rca_factories
            register_rca_factories(self.slicer.view_manager, self.server)
        self.layouts = LayoutManager(self.slicer.scene, self.slicer.view_manager, self.server)
        self.layouts.register_layout_dict(LayoutManager.default_grid_configuration())
        self.data_root = data_root
        self.studies = StudyLoader(self.slicer, data_root, upload_limit_mb)
        self.volume = None
        self.segmentation = None

        state = self.server.state
        state.trame__title = "mmrtm-web"
        state.presets = self.volume_rendering.preset_names()
        state.preset = preset if preset in state.presets else (state.presets[0] if state.presets else "")
        state.material_presets = [VOLUME_PROPERTY_MATERIALS] + material_presets()
        state.material_preset = VOLUME_PROPERTY_MATERIALS
        state.methods = list(METHODS)
        state.method = state.methods[0]
        state.studies = data_root.studies()
        state.study = ""
        state.series_items = []  # the chosen DICOM folder's series, when it has more than one
        state.series = None
        state.shown = ""  # the study shown, as the data root names it
        state.message = ""
        state.shift, state.shift_range = 0.0, [-1000.0, 1000.0]
        state.samples_per_render, state.maximum_samples, state.noise_target = 4, maximum_samples, 0.0
        state.samples, state.noise, state.refining, state.frames = 0, 0.0, False, 0
        state.displays, state.display = list(DISPLAYS), DEFAULT_DISPLAY
        state.display_status, state.denoises, state.denoise_seconds = "", 0, 0.0
        state.opacity_points, state.colour_points = [], []
        state.segmentation_path = ""
        state.segments = []
        state.upload_limit = self.studies.upload_limit
        state.upload = None
        state.change("preset")(self.on_preset)
        state.change("method")(self.on_method)
        state.change("study")(self.on_study_chosen)
        state.change("shift")(self.on_shift)
        state.change("samples_per_render", "maximum_samples", "noise_target", "material_preset",
                     "display")(self.on_settings)
        state.change("upload")(self.on_upload)
        self.server.controller.open_study = self.on_open_study
        self.server.controller.open_segmentation = self.on_open_segmentation
        self.server.controller.segment_visibility = self.on_segment_visibility
        self.server.controller.segment_colour = self.on_segment_colour
        self.server.controller.opacity_point = self.on_opacity_point
        self.server.controller.colour_point = self.on_colour_point
        self.server.trigger("screenshot")(self.screenshot_png)

        from .page import build_page
        self.ui = build_page(self.server, self.layouts)
        self.layouts.set_layout("3D Primary")
        if streaming != "progressive":
            self.report_renders_of_trame_rca()
        path = data_root.resolve(volume_path)
        try:
            self.show(self.studies.load(path))
        except ValueError as e:
            raise ValueError("%s: %s" % (path, e)) from e
        state.shown = os.path.relpath(path, data_root.folder)

    def report_renders_of_trame_rca(self):
        """The page's refinement state under trame-rca's scheduler, which
        has no per-frame hook: after every render of the 3D view."""
        from .streaming import path_traced_mappers

        window = self.slicer.view_manager.get_threed_views()[0].render_window()
        renders = [0]

        def rendered(*_):
            renders[0] += 1
            self.on_frame(path_traced_mappers(window), renders[0])

        window.AddObserver("EndEvent", rendered)

    # The study, its display node and its segmentation.

    def show(self, volume):
        """Shows `volume` path traced and in the slice views, in place of
        the study shown before."""
        self.remove_segmentation()
        if self.volume is not None:
            shown = self.volume_rendering.get_vr_display_node(self.volume)
            if shown is not None:
                self.slicer.scene.RemoveNode(shown)
            self.slicer.scene.RemoveNode(self.volume)
        self.volume = volume
        self.slicer.display_manager.show_volume(volume, vr_preset=self.server.state.preset, do_reset_views=True)
        self.configure(self.display_node())
        low, high = volume.GetImageData().GetScalarRange()
        width = max(high - low, 1.0)
        with self.server.state as state:
            state.shift, state.shift_range = 0.0, [-width / 2, width / 2]
        self.show_transfer_functions()

    def volume_property(self):
        display = self.display_node()
        node = display.GetVolumePropertyNode() if display is not None else None
        return node.GetVolumeProperty() if node is not None else None

    def show_transfer_functions(self):
        """The editor's lists, from the volume property as it is now."""
        volume_property = self.volume_property()
        with self.server.state as state:
            state.opacity_points = transfer_functions.opacity_points(volume_property) if volume_property else []
            state.colour_points = transfer_functions.colour_points(volume_property) if volume_property else []

    def display_node(self):
        return self.volume_rendering.get_vr_display_node(self.volume) if self.volume is not None else None

    def configure(self, display):
        """Our settings on a display node of the chosen method (Volume
        Rendering makes a new node at each method change)."""
        state = self.server.state
        wanted = METHODS[state.method]
        if display is None or not display.IsA(wanted):
            raise RuntimeError("Volume Rendering made a %s, not a %s"
                               % (display.GetClassName() if display else "no node", wanted))
        if display.IsA(METHOD):
            display.SetAsynchronousRefinement(True)
            display.SetSamplesPerRender(max(1, int(state.samples_per_render)))
            display.SetMaximumSamples(max(1, int(state.maximum_samples)))
            display.SetNoiseTarget(max(0.0, min(1.0, float(state.noise_target) / 100)))
            display.SetDenoisingMode(DISPLAYS.get(state.display, DISPLAYS[DEFAULT_DISPLAY]))
            materials = state.material_preset
            display.SetMaterialPreset(materials if materials in state.material_presets[1:] else "")
            if self.segmentation is not None:
                display.SetAndObserveSegmentationNodeID(self.segmentation.GetID())

    def remove_segmentation(self):
        if self.segmentation is not None:
            display = self.display_node()
            if display is not None and display.IsA(METHOD):
                display.SetAndObserveSegmentationNodeID(None)
            self.slicer.scene.RemoveNode(self.segmentation)
            self.segmentation = None
        self.server.state.segments = []

    def segments(self):
        """The page's list of the segmentation's segments."""
        if self.segmentation is None:
            return []
        listed = []
        segmentation, display = self.segmentation.GetSegmentation(), self.segmentation.GetDisplayNode()
        for index in range(segmentation.GetNumberOfSegments()):
            segment_id = segmentation.GetNthSegmentID(index)
            segment = segmentation.GetSegment(segment_id)
            listed.append({"id": segment_id, "name": segment.GetName(), "colour": hex_colour(segment.GetColor()),
                           "visible": bool(display.GetSegmentVisibility(segment_id)) if display else True})
        return listed

    # The page's actions.

    def on_study_chosen(self, study, **_):
        """A DICOM folder with several series: the page offers them."""
        items, chosen = [], None
        try:
            series = self.studies.series_of(study)
            if len(series) > 1:
                items = [{"title": s.label(), "value": s.uid} for s in series]
                chosen = series[0].uid
        except ValueError:
            pass  # Open says what is wrong with it
        with self.server.state as state:
            state.series_items, state.series = items, chosen

    def open_from_data_root(self, typed, load):
        """load(path) of the path the page typed or chose, resolved in the
        data root; None, with a message in the page naming the path as
        typed, when it leads outside the root or cannot be read (the
        server goes on)."""
        try:
            path = self.data_root.resolve(typed)
        except ValueError as e:
            self.server.state.message = str(e)
            return None
        try:
            return load(path)
        except ValueError as e:
            self.server.state.message = "'%s': %s" % (typed, e)
            return None

    def on_open_study(self, study, series=None):
        """The page's Open: the study typed or chosen (and the chosen series
        of a DICOM folder of several)."""
        state = self.server.state
        volume = self.open_from_data_root(study, lambda path: self.studies.load(path, series=series))
        if volume is None:
            return
        self.show(volume)
        state.message = ""
        state.shown = study

    def on_upload(self, upload, **_):
        if not upload:
            return
        state = self.server.state
        try:
            volume, name = self.studies.load_upload(upload)
        except ValueError as e:
            state.message = str(e)
        else:
            self.show(volume)
            state.message = ""
            state.shown = "%s (uploaded)" % name
        state.upload = None

    def on_open_segmentation(self, segmentation_path):
        state = self.server.state
        segmentation = self.open_from_data_root(
            segmentation_path, lambda path: self.studies.load_segmentation(path, self.volume))
        if segmentation is None:
            return
        self.remove_segmentation()
        self.segmentation = segmentation
        display = self.display_node()
        if display is not None and display.IsA(METHOD):
            display.SetAndObserveSegmentationNodeID(segmentation.GetID())
        state.segments = self.segments()
        state.message = ""

    def on_segment_visibility(self, segment_id, visible):
        if self.segmentation is not None and self.segmentation.GetDisplayNode() is not None:
            self.segmentation.GetDisplayNode().SetSegmentVisibility(str(segment_id), bool(visible))
            self.server.state.segments = self.segments()

    def on_segment_colour(self, segment_id, colour):
        segment = self.segmentation.GetSegmentation().GetSegment(str(segment_id)) if self.segmentation else None
        if segment is None or not isinstance(colour, str) or len(colour) != 7 or not colour.startswith("#"):
            return
        try:
            segment.SetColor(*(int(colour[i:i + 2], 16) / 255 for i in (1, 3, 5)))
        except ValueError:
            return
        self.server.state.segments = self.segments()

    def on_method(self, method, **_):
        if method not in METHODS:
            return
        self.volume_rendering_logic.SetDefaultRenderingMethod(METHODS[method])
        if self.volume is not None:
            self.volume_rendering_logic.ChangeVolumeRenderingMethod(METHODS[method])
            self.configure(self.display_node())

    def on_preset(self, preset, **_):
        if self.volume is not None and preset:
            self.volume_rendering.apply_preset(self.display_node(), preset)
            self.server.state.shift = 0.0
            self.show_transfer_functions()

    def on_shift(self, shift, **_):
        """Slicer's shift: the preset's functions moved along the values."""
        if self.volume is None:
            return
        try:
            shift = float(shift)
        except (TypeError, ValueError):
            return
        self.volume_rendering.set_absolute_vr_shift_from_preset(self.volume, self.server.state.preset, shift)
        self.show_transfer_functions()

    def on_opacity_point(self, index, field, value):
        """The editor: a point of the opacity function moved (field "x")
        or set to another opacity (field "y")."""
        volume_property = self.volume_property()
        if volume_property is not None and field in ("x", "y") and transfer_functions.set_opacity_point(
                volume_property, index, **{field: value}):
            self.show_transfer_functions()

    def on_colour_point(self, index, colour):
        volume_property = self.volume_property()
        if volume_property is not None and transfer_functions.set_colour_point(volume_property, index, colour):
            self.show_transfer_functions()

    def on_settings(self, **_):
        """Samples per pass, maximum samples, noise target, materials, display."""
        display = self.display_node()
        if display is not None and display.IsA(METHOD):
            try:
                self.configure(display)
            except (TypeError, ValueError):
                pass  # a field being typed

    def on_frame(self, mappers, frames):
        """The refinement state of the frame just rendered, for the page."""
        with self.server.state as state:
            state.frames = frames
            if not mappers:
                state.samples, state.noise, state.refining, state.display_status = 0, 0.0, False, ""
                return
            mapper = mappers[0]
            state.samples = mapper.GetAccumulatedSamples()
            state.noise = round(100 * mapper.GetRelativeNoise(), 2)
            state.refining = not mapper.IsConverged()
            state.display_status = mapper.GetDisplayStatus()
            state.denoises = mapper.GetNumberOfDenoises()
            state.denoise_seconds = round(mapper.GetDenoisingSeconds(), 1)

    def screenshot_png(self):
        """The 3D view as it is now, as PNG bytes (lossless, unlike the
        stream's JPEG frames)."""
        from vtkmodules.vtkIOImage import vtkPNGWriter
        from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

        window = self.slicer.view_manager.get_threed_views()[0].render_window()
        capture = vtkWindowToImageFilter()
        capture.SetInput(window)
        capture.SetInputBufferTypeToRGB()
        capture.ReadFrontBufferOff()
        capture.Update()
        writer = vtkPNGWriter()
        writer.WriteToMemoryOn()
        writer.SetInputConnection(capture.GetOutputPort())
        writer.Write()
        return bytes(memoryview(writer.GetResult()))


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
    from .data_root import DataRoot
    if not os.path.exists(args.volume):
        sys.exit("mmrtm-web: error: %s: no such file or folder%s" % (args.volume, (
            " (the default study comes with Debian's invesalius-examples package)"
            if args.volume == DEFAULT_STUDY else "")))
    try:
        root = DataRoot(args.data_root or os.path.dirname(os.path.abspath(args.volume.rstrip("/"))))
    except ValueError as e:
        sys.exit("mmrtm-web: error: %s" % e)
    try:
        token, context = access_settings(args)
    except AccessError as e:
        sys.exit("mmrtm-web: error: %s" % e)
    if not is_loopback(args.host) and context is None:
        print("mmrtm-web: warning: serving on %s without TLS (--insecure): the key and the images cross the "
              "network in the clear" % args.host, file=sys.stderr, flush=True)
    if token is None:
        print("mmrtm-web: warning: no access key (--no-token): every user and process of this machine can open "
              "the studies", file=sys.stderr, flush=True)
    try:
        viewer = WebViewer(os.path.abspath(args.volume), root, preset=args.preset,
                           maximum_samples=args.maximum_samples, upload_limit_mb=args.upload_limit_mb,
                           streaming=args.streaming)
    except ValueError as e:
        sys.exit("mmrtm-web: error: %s" % e)
    serve(viewer, args.host, args.port, token, context)


def serve(viewer, host, port, token, context):
    """Starts the viewer's server behind the key (when there is one) and TLS
    (when `context`), and prints the address to open once it listens."""
    server = viewer.server

    def bind(web_server):
        # The key's check first: a refused request is not a browser.
        if token is not None:
            web_server.app.middlewares.append(AccessKey(token, secure_cookie=context is not None).middleware())
        web_server.app.middlewares.append(viewer.presence.middleware())
        if context is not None:
            web_server.config["ssl"] = context

    server.controller.on_server_bind.add(bind)
    server.controller.on_server_ready.add(lambda **_: print(
        "mmrtm-web: open %s" % address_to_open(host, server.port, token, context is not None), flush=True))
    server.start(host=host, port=port, open_browser=False, show_connection_info=False)


if __name__ == "__main__":
    main()
