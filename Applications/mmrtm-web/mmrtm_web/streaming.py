"""Streaming fitted to a progressive renderer: one frame per change or
finished sample pass, never more than one render in flight, and none while
no browser is connected.

trame-rca's image scheduler renders whenever asked and re-renders each
frame at a higher JPEG quality shortly after. Our Slicer pipeline asks for
another render at the end of every render until the image converges, so
with it each sample pass was captured, encoded and pushed several times,
and with synchronous refinement the server's event loop was blocked for a
whole pass (a camera drag waited for refinement to end). With the display
node's AsynchronousRefinement, a render returns at once (the first pass
after a change is rendered in it, a fast preview during interaction) and
the next pass runs on the tracer's threads. This scheduler then:

- renders when the page or the scene asks (a camera move, a preset, a
  resize): at once, between passes; a change outside an interaction is
  shown first as a preview (low resolution, tens of milliseconds), then
  by its first full pass;
- drops the requests made during its own render (the pipeline's "render
  again, not converged yet"), and instead watches the mappers: when the
  pass in flight has finished it renders once, which draws that pass and
  starts the next, and pushes that frame (a render that only starts a
  pass is not pushed);
- renders the still frame after an interaction ends (trame-rca's
  interactor does not render then; the last frame was a preview);
- pushes every frame at one JPEG quality (no second, still-quality render);
- renders nothing while no browser is connected (a request waits for one).
"""
import asyncio

from trame_rca.schedulers import RcaImageRenderScheduler


def path_traced_volumes(render_window):
    """The window's visible volumes that our mapper draws."""
    found = []
    renderers = render_window.GetRenderers()
    renderers.InitTraversal()
    for _ in range(renderers.GetNumberOfItems()):
        volumes = renderers.GetNextItem().GetVolumes()
        volumes.InitTraversal()
        for _ in range(volumes.GetNumberOfItems()):
            volume = volumes.GetNextVolume()
            mapper = volume.GetMapper()
            if volume.GetVisibility() and mapper is not None and mapper.IsA("vtkMultiMaterialVolumeMapper"):
                found.append(volume)
    return found


def path_traced_mappers(render_window):
    """Our mappers among the window's visible volumes."""
    return [volume.GetMapper() for volume in path_traced_volumes(render_window)]


class ProgressiveRenderScheduler(RcaImageRenderScheduler):
    """trame-rca's image scheduler with the render loop above. `presence`
    says whether a browser is connected; `on_frame(mappers, frames)` is
    called after each render with the frames pushed so far (the page's
    refinement status); `network_completion()` gives an awaitable that
    ends when the messages already handed to the network have been sent
    (trame's `server.network_completion`)."""

    # How often the pass in flight is checked: the delay between a pass's
    # end and its frame's capture, at most.
    POLL_S = 0.01

    # How long a preview may take to be encoded and sent before the first
    # full pass starts anyway.
    PREVIEW_SEND_S = 0.25

    def __init__(self, window, *, presence, network_completion, on_frame=None, quality=80, **kwargs):
        kwargs["interactive_quality"] = quality
        kwargs["still_quality"] = quality
        self.presence = presence
        self.on_frame = on_frame
        self.network_completion = network_completion
        self.frames = 0
        self.stalled_at = None
        self.pushed = None  # progress() when the last frame was rendered
        self.shown_scene = None  # scene() when the last frame was rendered
        # The VTK window behind trame-rca's area: its `render_window`
        # property renders, which this must not do to look at the mappers.
        self.render_window = window._vtk_render_window
        super().__init__(window, **kwargs)
        presence.arrival_listeners.append(self.schedule_render)
        presence.departure_listeners.append(self.end_abandoned_interaction)

    def mappers(self):
        return path_traced_mappers(self.render_window)

    async def _next_render(self):
        """Waits until a frame is due: a request, or (while refining) the
        end of the pass in flight. Returns False when closing."""
        while not self._is_closing:
            if not self.presence:
                await asyncio.sleep(0.1)
                continue
            if self._request_event.is_set():
                return True
            mappers = self.mappers()
            if any(m.IsRefining() for m in mappers):
                await asyncio.sleep(self.POLL_S)
                continue
            # Not converged: a pass has ended (draw it, start the next), a
            # change's first pass was drawn (start the next), or an
            # interaction has ended and the last frame was its preview
            # (trame-rca's interactor does not render at the end of an
            # interaction, so nothing else asks), unless _render found that
            # rendering again would give nothing new.
            if any(not m.IsConverged() for m in mappers) and self.progress(mappers) != self.stalled_at:
                return True
            try:
                await asyncio.wait_for(self._request_event.wait(), timeout=0.25)
            except asyncio.TimeoutError:
                pass
        return False

    def progress(self, mappers):
        """What a render may change: the samples, the denoised images made
        (a denoise in the background ends like a pass), and whether the
        window renders previews (an interaction sets its desired update
        rate)."""
        return ([(m.GetAccumulatedSamples(), m.GetNumberOfDenoises()) for m in mappers],
                self.render_window.GetDesiredUpdateRate())

    def scene(self):
        """What restarts the refinement when it changes: the view's size,
        each camera, and each of our volumes: its matrix by value (the
        Slicer pipeline sets it again at every update, as it does the
        mapper's clipping planes, and leaves the comparison to the mapper),
        its visibility, and the modification times of its property and
        input and the mapper's as far as tracing goes (compared by value in
        the mapper: a raised maximum leaves it as it was). A request with the
        scene as it was (a browser that connects and sends the view's size
        as it is, a setting that keeps the samples) is answered with the
        frame as it is, without a preview: a preview would stop the pass in
        flight and start the accumulation again. Something missed here only
        costs a change its preview."""
        cameras = []
        renderers = self.render_window.GetRenderers()
        renderers.InitTraversal()
        for _ in range(renderers.GetNumberOfItems()):
            camera = renderers.GetNextItem().GetActiveCamera()
            cameras.append((camera.GetPosition(), camera.GetFocalPoint(), camera.GetViewUp(), camera.GetViewAngle(),
                            camera.GetParallelProjection(), camera.GetParallelScale()))
        volumes = []
        for volume in path_traced_volumes(self.render_window):
            mapper = volume.GetMapper()
            data = mapper.GetInput()
            matrix = volume.GetMatrix()
            volumes.append((tuple(matrix.GetElement(i, j) for i in range(4) for j in range(4)), volume.GetVisibility(),
                            volume.GetProperty().GetMTime() if volume.GetProperty() else 0, mapper.GetTracingMTime(),
                            data.GetMTime() if data else 0))
        return self.render_window.GetSize(), cameras, volumes

    def push_frame(self):
        self._render_frame(self._interactive_quality)
        self.frames += 1

    def interacting(self):
        return self.render_window.GetDesiredUpdateRate() > self.render_window.GetInteractor().GetStillUpdateRate()

    def end_abandoned_interaction(self):
        """A browser left: a drag still in progress may be its own, whose
        button's release will never come (the interaction would hold the
        view in its preview for every other browser); the buttons are
        released where the pointer last was, which moves nothing."""
        if not self.interacting():
            return
        interactor = self.render_window.GetInteractor()
        interactor.LeftButtonReleaseEvent()
        interactor.MiddleButtonReleaseEvent()
        interactor.RightButtonReleaseEvent()
        self.schedule_render()

    async def push_preview(self):
        """A change outside an interaction (a preset, an edit, a resize)
        shown first as an interaction's preview, which takes tens of
        milliseconds, before the first full pass, which takes a second or
        more on a CPU and holds the server meanwhile: the preview is sent
        on its way before that pass starts."""
        still = self.render_window.GetDesiredUpdateRate()
        self.render_window.SetDesiredUpdateRate(self.render_window.GetInteractor().GetDesiredUpdateRate())
        pushed = self._last_push_time_ms
        try:
            self.push_frame()
        finally:
            self.render_window.SetDesiredUpdateRate(still)
        loop = asyncio.get_running_loop()
        deadline = loop.time() + self.PREVIEW_SEND_S
        # Encoded (on trame-rca's thread) and handed to wslink's publish...
        while self._last_push_time_ms == pushed and loop.time() < deadline:
            await asyncio.sleep(0.005)
        # ... and sent: publish only schedules the send, which a pass
        # started now would hold back until the pass ends (the preview
        # would arrive with the first pass, a second late).
        if loop.time() < deadline:
            try:
                await asyncio.wait_for(self.network_completion(), timeout=deadline - loop.time())
            except asyncio.TimeoutError:
                pass

    async def _render(self):
        while await self._next_render():
            requested = self._request_event.is_set()
            self._request_event.clear()
            mappers = self.mappers()
            before = self.progress(mappers)
            changed = requested and mappers and not self.interacting() and self.scene() != self.shown_scene
            if changed:
                await self.push_preview()
            elif not requested and before == self.pushed:
                # Asked by nothing: a pass has ended, or a change's first
                # pass was drawn and this render only starts the next one
                # in the background. Only a render that drew new samples
                # is captured (by rendering again, which only redraws).
                self.render_window.Render()
                if self.progress(self.mappers()) != before:
                    self.push_frame()
            else:
                self.push_frame()
            # The requests made during the render are the pipeline's
            # "not converged, render again": _next_render answers them
            # when the pass ends.
            self._request_event.clear()
            mappers = self.mappers()
            after = self.progress(mappers)
            self.pushed = after
            self.shown_scene = self.scene()
            # Nothing more comes of rendering again without a request or a
            # change of mode: after an interaction's preview (no samples
            # accumulate), or after a render that was not asked for and
            # neither drew samples nor started a pass.
            # A change's preview is followed by its first pass.
            preview = mappers and not any(samples for samples, _ in after[0]) and not changed
            idle = not any(m.IsRefining() for m in mappers)
            self.stalled_at = after if idle and (preview or (not requested and after == before)) else None
            if self.on_frame is not None:
                self.on_frame(mappers, self.frames)
            await asyncio.sleep(0)  # the browser's events first


def register_view_factories(view_manager, server, presence, on_frame):
    """trame-slicer's remote views: its slice views as they are, its 3D
    view streamed by ProgressiveRenderScheduler."""
    from trame_slicer.app.ui import create_vertical_slice_view_gutter_ui, create_vertical_view_gutter_ui
    from trame_slicer.rca_view import rca_view_factory

    class ThreeDViewFactory(rca_view_factory.RemoteThreeDViewFactory):
        def _create_view(self, view, scene, app_logic):
            # trame-slicer makes its scheduler inline, by the module's name
            # for it; ours stands in for it while this view is made.
            class Scheduler(ProgressiveRenderScheduler):
                def __init__(self, window, **kwargs):
                    super().__init__(window, presence=presence, on_frame=on_frame,
                                     network_completion=lambda: server.network_completion, **kwargs)

            original = rca_view_factory.RcaImageRenderScheduler
            rca_view_factory.RcaImageRenderScheduler = Scheduler
            try:
                return super()._create_view(view, scene, app_logic)
            finally:
                rca_view_factory.RcaImageRenderScheduler = original

    view_manager.register_factory(rca_view_factory.RemoteSliceViewFactory(
        server, populate_view_ui_f=create_vertical_slice_view_gutter_ui))
    view_manager.register_factory(ThreeDViewFactory(server, populate_view_ui_f=create_vertical_view_gutter_ui))
