"""The "Sunbeam" render engine: F12 runs `sunbeam-eval render` (the CPU reference), the
viewport's rendered mode `sunbeam-play --headless` (the GPU player), on the scene that
export.py writes into a temporary folder; the tools' linear EXR becomes Blender's render
result, so Blender's colour management (view transform, exposure, look) applies after it.

Blender's own engines cannot draw the material (EEVEE has no custom shading code, Cycles' OSL
no custom closures), so the engine hands the scene to Sunbeam the way external renderers do.
"""

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


VIEWPORT_IMAGE = "Sunbeam Viewport"


def _square_root(n):
    root = int(round(n ** 0.5))
    return root if root * root == n else None


def _frame_texture(path):
    """A GPU texture of the linear EXR at `path`, through one reused image data-block (it has no
    users, so it is not saved with the file)."""
    image = bpy.data.images.get(VIEWPORT_IMAGE)
    if image is None:
        image = bpy.data.images.load(path)
        image.name = VIEWPORT_IMAGE
    else:
        image.filepath = path
        image.reload()
    texture = gpu.texture.from_image(image)
    image.pixels[0]  # read the file now: the temporary folder goes after this draw
    return texture


class SunbeamRenderEngine(bpy.types.RenderEngine):
    bl_idname = "SUNBEAM"
    bl_label = "Sunbeam"
    bl_use_preview = False
    bl_use_postprocess = True

    _preview = None  # (thread, holder) of the viewport's running sunbeam-play
    _texture = None  # the last finished viewport frame

    # ------------------------------------------------------------ final render (F12)

    def render(self, depsgraph):
        scene = depsgraph.scene
        samples = scene.sunbeam.samples
        if _square_root(samples) is None:
            self.report({"ERROR"}, f"Render Properties > Sunbeam > Samples: {samples} is not a "
                        "square number (1, 4, 9, 16, ...)")
            return
        width, height = export.render_size(scene)
        warnings = []
        try:
            with tempfile.TemporaryDirectory(prefix="sunbeam-render-") as tmp:
                camera = export.camera_from_object(scene, scene.camera, warnings)
                scene_json = export.write_scene(
                    depsgraph, camera, (width, height), tmp, "sunbeam-eval", self.test_break,
                    self._progress, warnings)
                frame = os.path.join(tmp, "frame.exr")
                self._progress(0.5, f"sunbeam-eval render: {width} x {height}, {samples} samples")
                tools.run("sunbeam-eval", ["render", scene_json, "-o", frame, "-q",
                                           "--samples", str(samples)], self.test_break)
                self._load_result(frame, width, height)
                self._progress(1.0, "Done")
        except Cancelled:
            return
        except SunbeamError as e:
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

    def view_update(self, context, depsgraph):
        self._start_preview(context, depsgraph)

    def _start_preview(self, context, depsgraph):
        """Export in this (the main) thread, then run sunbeam-play in a worker thread."""
        self._cancel_preview()
        region, rv3d, space = context.region, context.region_data, context.space_data
        if not rv3d.is_perspective:
            self.report({"ERROR"}, "Viewport: Sunbeam renders perspective views only")
            return
        inv = rv3d.view_matrix.inverted()
        fov = 2.0 * math.degrees(math.atan(1.0 / rv3d.window_matrix[1][1]))
        size = (region.width, region.height)
        holder = {"cancel": False, "frame": None, "error": None,
                  "tmp": tempfile.TemporaryDirectory(prefix="sunbeam-view-")}
        warnings = []
        try:
            camera = export.view_camera(inv.translation, inv.to_3x3() @ Vector((0, 0, -1)),
                                        inv.to_3x3() @ Vector((0, 1, 0)), fov,
                                        space.clip_start, "Viewport")
            scene_json = export.write_scene(depsgraph, camera, size, holder["tmp"].name,
                                            "sunbeam-play", lambda: holder["cancel"],
                                            lambda *_: None, warnings)
        except SunbeamError as e:
            holder["tmp"].cleanup()
            self.report({"ERROR"}, str(e))
            return
        frames = depsgraph.scene.sunbeam.preview_frames

        def work():
            frame = os.path.join(holder["tmp"].name, "frame.exr")
            try:
                tools.run("sunbeam-play", [scene_json, "--headless", "-o", frame, "-q",
                                           "--frames", str(frames)], lambda: holder["cancel"])
                holder["frame"] = frame
            except Cancelled:
                pass
            except SunbeamError as e:
                holder["error"] = str(e)

        thread = threading.Thread(target=work, daemon=True)
        self._preview = (thread, holder)
        thread.start()

    def _cancel_preview(self):
        if self._preview:
            thread, holder = self._preview
            holder["cancel"] = True
            thread.join()
            holder["tmp"].cleanup()
            self._preview = None

    def view_draw(self, context, depsgraph):
        if self._preview:
            thread, holder = self._preview
            if thread.is_alive():
                self.update_stats("Sunbeam", "sunbeam-play: rendering the preview")
                self.tag_redraw()
            else:
                self._preview = None
                if holder["error"]:
                    self.report({"ERROR"}, holder["error"])
                elif holder["frame"]:
                    self._texture = _frame_texture(holder["frame"])
                    self.update_stats("Sunbeam", "Preview done")
                holder["tmp"].cleanup()
        if self._texture is None:
            return
        gpu.state.blend_set("ALPHA_PREMULT")
        self.bind_display_space_shader(depsgraph.scene)
        draw_texture_2d(self._texture, (0, 0), context.region.width, context.region.height)
        self.unbind_display_space_shader()
        gpu.state.blend_set("NONE")


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
    bpy.utils.unregister_class(SunbeamRenderEngine)
    for panel in get_panels():
        panel.COMPAT_ENGINES.discard("SUNBEAM")
