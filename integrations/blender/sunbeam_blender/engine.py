"""The "Sunbeam" render engine: F12 runs `sunbeam-eval render` (the CPU reference), the
viewport's rendered mode `sunbeam-play --headless` (the GPU player), on the scene that
export.py writes into a temporary folder; the tools' linear EXR becomes Blender's render
result, so Blender's colour management (view transform, exposure, look) applies after it.

Blender's own engines cannot draw the material (EEVEE has no custom shading code, Cycles' OSL
no custom closures), so the engine hands the scene to Sunbeam the way external renderers do.
"""

import atexit
import math
import os
import tempfile
import threading

import bpy
import gpu
from gpu_extras.presets import draw_texture_2d
from mathutils import Vector

from . import export, exr, tools
from .tools import Cancelled, SunbeamError


# The viewport's running previews, thread -> holder: when Blender quits or the add-on is
# disabled they are cancelled (tools.run kills the child), or a sunbeam-play would outlive it.
_PREVIEWS = {}


def _stop_previews():
    running = list(_PREVIEWS.items())
    for _, holder in running:
        holder["cancel"] = True
    for thread, _ in running:
        thread.join(timeout=5.0)
    _PREVIEWS.clear()


atexit.register(_stop_previews)


def _is_square(n):
    root = int(round(n ** 0.5))
    return root * root == n


def _frame_texture(path):
    """A GPU texture of the linear EXR at `path`, made from its pixels directly: view_draw may
    not write to Blender's data (an image data-block's name or file path raises "Writing to ID
    classes in this context is not allowed"), so no image data-block is involved."""
    width, height, data = exr.read_rgba_bottom_up(path)
    buffer = gpu.types.Buffer("FLOAT", len(data), data)
    return gpu.types.GPUTexture((width, height), format="RGBA32F", data=buffer)


class SunbeamRenderEngine(bpy.types.RenderEngine):
    bl_idname = "SUNBEAM"
    bl_label = "Sunbeam"
    bl_use_preview = False
    bl_use_postprocess = True

    _preview = None  # (thread, holder) of the viewport's running sunbeam-play
    _texture = None  # the last finished viewport frame
    _export_dir = None  # the viewport's exported meshes and World
    _doc = None  # their scene document (no camera or size)
    _exported = False  # an export was started for the scene as it is
    _view = None  # (camera, size) of the last viewport frame started
    _runs = 0

    # ------------------------------------------------------------ final render (F12)

    def render(self, depsgraph):
        scene = depsgraph.scene
        samples = scene.sunbeam.samples
        if not _is_square(samples):
            self.report({"ERROR"}, f"Render Properties > Sunbeam > Samples: {samples} is not a "
                        "square number (1, 4, 9, 16, ...)")
            return
        width, height = export.render_size(scene)
        warnings = []
        try:
            with tempfile.TemporaryDirectory(prefix="sunbeam-render-") as tmp:
                camera = export.camera_from_object(scene, scene.camera, warnings)
                doc = export.build_scene(depsgraph, tmp, "sunbeam-eval", self.test_break,
                                         self._progress, warnings)
                scene_json = export.save_scene(doc, camera, (width, height),
                                               os.path.join(tmp, "scene.json"))
                frame = os.path.join(tmp, "frame.exr")
                self._progress(0.5, f"sunbeam-eval render: {width} x {height}, {samples} samples")
                tools.run("sunbeam-eval", ["render", scene_json, "-o", frame, "-q",
                                           "--samples", str(samples)], self.test_break)
                self._load_result(frame, width, height)
                self._progress(1.0, "Done")
        except Cancelled:
            return
        except (SunbeamError, OSError) as e:
            self.report({"ERROR"}, str(e))
            return
        for w in warnings:
            self.report({"WARNING"}, w)

    def _load_result(self, frame, width, height):
        """The tool's linear frame as the Combined pass (Blender's rows are bottom-up)."""
        try:
            w, h, pixels = exr.read_rgb(frame)
        except (OSError, ValueError) as e:
            raise SunbeamError(f"Render: {e}") from None
        if (w, h) != (width, height):
            raise SunbeamError(f"Render: {frame} is {w} x {h}, not {width} x {height}")
        rect = []
        for j in range(h - 1, -1, -1):
            rect.extend((r, g, b, 1.0) for r, g, b in pixels[j * w:(j + 1) * w])
        result = self.begin_result(0, 0, width, height)
        result.layers[0].passes["Combined"].rect = rect
        self.end_result(result)

    def _progress(self, fraction, text):
        self.update_progress(fraction)
        self.update_stats("Sunbeam", text)

    # ------------------------------------------------------------ viewport (rendered mode)
    #
    # view_update (a scene edit) schedules the export and bake: a timer runs it in the main
    # thread outside drawing, where operators (the glTF exporter) and selection changes are
    # allowed; it writes into a folder kept while the viewport renders. view_draw (also each
    # view change) runs sunbeam-play on that export with the view's camera in a worker thread
    # and draws the last finished frame.

    def view_update(self, context, depsgraph):
        if self._exported and not any(
                u.is_updated_geometry or u.is_updated_transform or u.is_updated_shading
                for u in depsgraph.updates):
            return  # e.g. a selection change (the export's own included): nothing to redo
        self._cancel_preview()
        self._exported, self._doc, self._view = True, None, None
        engine = self

        def export_later():
            try:
                engine._export_viewport()
            except ReferenceError:
                pass  # the viewport left rendered mode before the timer ran
            return None  # once

        bpy.app.timers.register(export_later)

    def _export_viewport(self):
        if self._export_dir is not None:
            self._export_dir.cleanup()
        self._export_dir = tempfile.TemporaryDirectory(prefix="sunbeam-view-")
        try:
            self._doc = export.build_scene(bpy.context.evaluated_depsgraph_get(),
                                           self._export_dir.name, "sunbeam-play",
                                           lambda: False, lambda *_: None, [])
        except SunbeamError as e:
            self.report({"ERROR"}, str(e))
            self.update_stats("Sunbeam", str(e))
        self.tag_redraw()

    def _start_preview(self, camera, size, frames):
        self._cancel_preview()
        self._runs += 1
        holder = {"cancel": False, "frame": None, "error": None}
        scene_json = export.save_scene(self._doc, camera, size,
                                       os.path.join(self._export_dir.name, "view.json"))
        frame = os.path.join(self._export_dir.name, f"view{self._runs}.exr")

        def work():
            try:
                preview_frame(scene_json, frame, frames, lambda: holder["cancel"])
                holder["frame"] = frame
            except Cancelled:
                pass
            except SunbeamError as e:
                holder["error"] = str(e)
            finally:
                _PREVIEWS.pop(thread, None)

        thread = threading.Thread(target=work, daemon=True)
        self._preview = (thread, holder)
        _PREVIEWS[thread] = holder
        thread.start()

    def _cancel_preview(self):
        if self._preview:
            thread, holder = self._preview
            holder["cancel"] = True
            thread.join()
            self._preview = None

    def view_draw(self, context, depsgraph):
        if self._doc is not None:
            try:
                view = viewport_camera(context)
            except SunbeamError as e:
                self.update_stats("Sunbeam", str(e))
                view = None
            if view is not None and view != self._view:
                self._view = view
                self._start_preview(*view, depsgraph.scene.sunbeam.preview_frames)
        if self._preview:
            thread, holder = self._preview
            if thread.is_alive():
                self.update_stats("Sunbeam", "sunbeam-play: rendering the preview")
                self.tag_redraw()
            else:
                self._preview = None
                if holder["error"]:
                    self.report({"ERROR"}, holder["error"])
                    self.update_stats("Sunbeam", holder["error"])
                elif holder["frame"]:
                    try:
                        self._texture = _frame_texture(holder["frame"])
                        self.update_stats("Sunbeam", "Preview done")
                    except (OSError, ValueError) as e:
                        self.report({"ERROR"}, f"Viewport: {e}")
                        self.update_stats("Sunbeam", f"Viewport: {e}")
                    os.remove(holder["frame"])
        if self._texture is None:
            return
        gpu.state.blend_set("ALPHA_PREMULT")
        self.bind_display_space_shader(depsgraph.scene)
        draw_texture_2d(self._texture, (0, 0), context.region.width, context.region.height)
        self.unbind_display_space_shader()
        gpu.state.blend_set("NONE")


def viewport_camera(context):
    """The scene camera and frame size of a 3D viewport (its view and projection matrices)."""
    region, rv3d = context.region, context.region_data
    if not rv3d.is_perspective:
        raise SunbeamError("Viewport: Sunbeam renders perspective views only")
    inv = rv3d.view_matrix.inverted()
    wm = rv3d.window_matrix
    fov = 2.0 * math.degrees(math.atan(1.0 / wm[1][1]))
    # An off-axis projection (a camera view with Shift): wm[0][2], wm[1][2] are the NDC
    # offsets, Sunbeam's shift times 2 m / w and 2 m / h (m the larger side).
    w, h = region.width, region.height
    m = max(w, h, 1)
    shift = (wm[0][2] * w / (2.0 * m), wm[1][2] * h / (2.0 * m))
    camera = export.view_camera(inv.translation, inv.to_3x3() @ Vector((0, 0, -1)),
                                inv.to_3x3() @ Vector((0, 1, 0)), fov,
                                context.space_data.clip_start, "Viewport", shift=shift)
    return camera, (region.width, region.height)


def preview_frame(scene_json, frame, frames, cancelled):
    """The viewport's frame: sunbeam-play's headless linear EXR of `scene_json`."""
    tools.run("sunbeam-play", [scene_json, "--headless", "-o", frame, "-q", "--frames", str(frames)],
              cancelled)


def get_panels():
    """Blender's panels that apply to any engine (camera, light, world, material slots...)."""
    extra = {"EEVEE_WORLD_PT_surface", "EEVEE_MATERIAL_PT_context_material", "DATA_PT_EEVEE_light"}
    exclude = {"VIEWLAYER_PT_filter", "VIEWLAYER_PT_layer_passes"}
    panels = []
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is not None and panel.__name__ not in exclude and (
                "BLENDER_RENDER" in engines or panel.__name__ in extra):
            panels.append(panel)
    return panels


def register():
    bpy.utils.register_class(SunbeamRenderEngine)
    for panel in get_panels():
        panel.COMPAT_ENGINES.add("SUNBEAM")


def unregister():
    _stop_previews()
    bpy.utils.unregister_class(SunbeamRenderEngine)
    for panel in get_panels():
        panel.COMPAT_ENGINES.discard("SUNBEAM")
