"""The page: the controls in a drawer, the refinement state in the
toolbar, Slicer's layout in the content. Class names on the controls are
what the browser test finds them by."""

# Sent by the browser only when under the server's limit (the server checks
# again): a larger file is refused before it is read.
UPLOAD_CHECK = ("(f) => { const file = Array.isArray(f) ? f[0] : f; if (!file) return;"
                " if (upload_limit <= 0 || file.size > upload_limit) {"
                " message = `'${file.name}': ${(file.size / 1048576).toFixed(0)} MiB, over the upload limit of"
                " ${(upload_limit / 1048576).toFixed(0)} MiB`; } else { upload = file; } }")

SCREENSHOT = "utils.download(`mmrtm-web-${samples}spp.png`, trigger('screenshot'), 'image/png')"


def build_page(server, layouts):
    from trame.widgets import vuetify3
    from trame_client.widgets import html
    from trame_client.widgets.html import Div
    from trame_vuetify.ui.vuetify3 import SinglePageWithDrawerLayout

    ctrl = server.controller
    with SinglePageWithDrawerLayout(server, width=320) as ui:
        ui.title.set_text("mmrtm-web: path tracing (MM-RTM)")
        with ui.toolbar:
            vuetify3.VSpacer()
            html.Span("{{ shown }}", classes="shown-study text-body-2 mr-4")
            # The accumulation, then what the view shows of it (the mapper's
            # display status: "denoised, 8 samples", "unbiased, 32 samples,
            # noise 2.1 %"); nothing is called converged before a sample.
            html.Span("{{ samples }} / {{ maximum_samples }} samples, noise {{ noise }} %"
                      " {{ refining ? '(refining)' : samples ? '(converged)' : '(starting)' }}",
                      v_if=("method.startsWith('Path')",), classes="refinement-status text-body-2 mr-2")
            html.Span("shown: {{ display_status }}", v_if=("method.startsWith('Path') && display_status",),
                      classes="display-status text-body-2 mr-2")
            # The denoiser's time since the server started (at most a
            # quarter of the refinement's).
            html.Span("denoiser {{ denoise_seconds }} s", v_if=("method.startsWith('Path') && denoises",),
                      classes="denoise-seconds text-caption mr-4")
            html.Span("{{ denoises }}", classes="denoise-count d-none")
            # Frames rendered since the server started: the browser test
            # compares it with the frames it received and the passes.
            html.Span("{{ frames }}", classes="frame-count d-none")
            vuetify3.VBtn("PNG", click=SCREENSHOT, prepend_icon="mdi-camera", variant="text", classes="screenshot")
            vuetify3.VProgressLinear(v_if=("refining && method.startsWith('Path')",),
                                     model_value=("100 * samples / Math.max(1, maximum_samples)",),
                                     absolute=True, location="bottom", color="primary",
                                     classes="refinement-progress")
        with ui.drawer:
            with vuetify3.VContainer(classes="d-flex flex-column ga-3"):
                html.Div("Study", classes="text-subtitle-2")
                vuetify3.VCombobox(v_model=("study",), items=("studies",), label="In the data root",
                                   density="compact", hide_details=True, classes="study-path")
                vuetify3.VSelect(v_if=("series_items.length",), v_model=("series",), items=("series_items",),
                                 label="Series", density="compact", hide_details=True, classes="series-select")
                # The button sends what the page shows: a state update may
                # still wait behind a render when the click arrives.
                vuetify3.VBtn("Open", click=(ctrl.open_study, "[study, series_items.length ? series : null]"),
                              classes="open-study")
                vuetify3.VFileInput(label="Upload (NRRD, NIfTI, .mha, .inv3)", density="compact",
                                    hide_details=True, show_size=True, classes="upload-input",
                                    update_modelValue=UPLOAD_CHECK)
                html.Div("Look", classes="text-subtitle-2 mt-2")
                vuetify3.VSelect(v_model=("preset",), items=("presets",), label="Preset", density="compact",
                                 hide_details=True, classes="preset-select")
                vuetify3.VSlider(v_model=("shift",), min=("shift_range[0]",), max=("shift_range[1]",),
                                 label="Shift", density="compact", hide_details=True, thumb_label=True,
                                 step=1, classes="shift-slider")
                vuetify3.VSelect(v_model=("material_preset",), items=("material_presets",),
                                 label="Materials (MM-RTM presets)", density="compact", hide_details=True,
                                 classes="material-preset-select")
                with vuetify3.VExpansionPanels(variant="accordion", classes="transfer-function-editor"):
                    with vuetify3.VExpansionPanel(title="Transfer functions"):
                        with vuetify3.VExpansionPanelText():
                            html.Div("Opacity: value, opacity", classes="text-caption")
                            with Div(v_for="(point, i) in opacity_points", key="'o' + i",
                                     classes="d-flex flex-row align-center ga-2 opacity-point"):
                                vuetify3.VTextField(model_value=("point.x",), type="number", density="compact",
                                                    hide_details=True, variant="underlined",
                                                    style="max-width: 90px", classes="opacity-x",
                                                    change=(ctrl.opacity_point, "[i, 'x', $event.target.value]"))
                                vuetify3.VSlider(model_value=("point.y",), min=0, max=1, step=0.01,
                                                 density="compact", hide_details=True, thumb_label=True,
                                                 classes="opacity-y",
                                                 update_modelValue=(ctrl.opacity_point, "[i, 'y', $event]"))
                            html.Div("Colour: value, colour", classes="text-caption mt-2")
                            with Div(v_for="(point, i) in colour_points", key="'c' + i",
                                     classes="d-flex flex-row align-center ga-2 colour-point"):
                                html.Span("{{ point.x }}", classes="text-body-2", style="min-width: 90px")
                                html.Input(type="color", value=("point.colour",),
                                           change=(ctrl.colour_point, "[i, $event.target.value]"),
                                           style="width: 28px; height: 22px")
                vuetify3.VSelect(v_model=("method",), items=("methods",), label="Rendering", density="compact",
                                 hide_details=True, classes="method-select")
                vuetify3.VSelect(v_model=("display",), items=("displays",), label="3D view shows",
                                 density="compact", hide_details=True, classes="display-select")
                html.Div("Refinement", classes="text-subtitle-2 mt-2")
                vuetify3.VTextField(v_model_number=("samples_per_render",), type="number", min=1,
                                    label="Samples per pass", density="compact", hide_details=True,
                                    classes="samples-per-render")
                vuetify3.VTextField(v_model_number=("maximum_samples",), type="number", min=1,
                                    label="Maximum samples", density="compact", hide_details=True,
                                    classes="maximum-samples")
                vuetify3.VTextField(v_model_number=("noise_target",), type="number", min=0, step=0.5,
                                    label="Noise target % (0: none)", density="compact", hide_details=True,
                                    classes="noise-target")
                html.Div("Segmentation", classes="text-subtitle-2 mt-2")
                vuetify3.VCombobox(v_model=("segmentation_path",), items=("studies",),
                                   label="Label map or segmentation", density="compact", hide_details=True,
                                   classes="segmentation-path")
                vuetify3.VBtn("Show as materials", click=(ctrl.open_segmentation, "[segmentation_path]"), classes="open-segmentation")
                with Div(v_for="segment in segments", key="segment.id",
                         classes="d-flex flex-row align-center segment-row"):
                    vuetify3.VCheckboxBtn(model_value=("segment.visible",), density="compact",
                                          update_modelValue=(ctrl.segment_visibility, "[segment.id, $event]"),
                                          classes="segment-visible")
                    html.Input(type="color", value=("segment.colour",),
                               change=(ctrl.segment_colour, "[segment.id, $event.target.value]"),
                               classes="segment-colour mr-2", style="width: 28px; height: 22px")
                    html.Span("{{ segment.name }}", classes="text-body-2 segment-name")
        with ui.content:
            vuetify3.VAlert(v_if=("message",), text=("message",), type="error", density="compact",
                            closable=True, classes="study-message")
            with Div(classes="fill-height d-flex flex-row flex-grow-1"):
                layouts.initialize_layout_grid(ui)
    return ui
