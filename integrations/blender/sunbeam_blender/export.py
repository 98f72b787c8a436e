"""Translating a Blender scene into a Sunbeam scene (docs/SCENE.md) in a temporary folder.

Everything is checked before any tool runs, so a bad input stops the render with a message
that names the object and the field and leaves nothing behind. Blender is z-up, Sunbeam (like
glTF) y-up: Blender's (x, y, z) is Sunbeam's (x, z, -y), the same axis change as the glTF
exporter's "+Y Up", so the exported meshes, the camera, the lights and the World agree.
"""

import json
import math
import os
import struct
import threading
from array import array

import bpy
from mathutils import Vector

from . import exr, tools
from .tools import SunbeamError

_INF = float("inf")
SPINE = "<spine>"  # in bake_source's flags: where bake() puts the spine file it writes


def to_sunbeam(v):
    """A Blender world vector in Sunbeam's (glTF's) y-up axes."""
    return [v[0], v[2], -v[1]]


def sunbeam_material(obj):
    """The first material of `obj` marked as a Sunbeam material, or None."""
    for slot in obj.material_slots:
        if slot.material and slot.material.sunbeam.enabled:
            return slot.material
    return None


def _base_color(obj):
    """The diffuse colour Blender shows for an object without a Sunbeam material."""
    mat = obj.active_material
    if mat is None:
        return [0.8, 0.8, 0.8]
    if mat.use_nodes and mat.node_tree:
        for node in mat.node_tree.nodes:
            if node.type in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE"):
                socket = node.inputs["Base Color" if node.type == "BSDF_PRINCIPLED" else "Color"]
                return list(socket.default_value[:3])
    return list(mat.diffuse_color[:3])


# ---------------------------------------------------------------- camera

def render_size(scene):
    """Blender's output size: resolution times percentage (integer division, as Blender)."""
    r = scene.render
    return (r.resolution_x * r.resolution_percentage // 100,
            r.resolution_y * r.resolution_percentage // 100)


def camera_from_object(scene, cam_obj, warnings):
    """The scene camera of Blender's active camera: eye, target, up, vertical field of view."""
    if cam_obj is None:
        raise SunbeamError("Scene: no active camera (Scene > Camera)")
    cam = cam_obj.data
    if cam.type != "PERSP":
        raise SunbeamError(f"Camera '{cam_obj.name}': Type: only perspective cameras are supported "
                           f"(not {cam.type.lower()})")
    r = scene.render
    width, height = render_size(scene)
    if r.pixel_aspect_x != r.pixel_aspect_y:
        raise SunbeamError(f"Scene '{scene.name}': Pixel Aspect: Sunbeam renders square pixels")
    fit = cam.sensor_fit
    if fit == "AUTO":
        fit, sensor = ("HORIZONTAL" if width >= height else "VERTICAL"), cam.sensor_width
    else:
        sensor = cam.sensor_width if fit == "HORIZONTAL" else cam.sensor_height
    half = sensor / (2.0 * cam.lens)
    if fit == "HORIZONTAL":
        half *= height / width
    # Blender's shift is in units of the side the sensor spans (the fit's: width for
    # horizontal, height for vertical), Sunbeam's of the larger side.
    side = width if fit == "HORIZONTAL" else height
    scale = side / max(width, height, 1)
    m = cam_obj.matrix_world
    return view_camera(m.translation, m.to_3x3() @ Vector((0, 0, -1)), m.to_3x3() @ Vector((0, 1, 0)),
                       2.0 * math.degrees(math.atan(half)), cam.clip_start, f"Camera '{cam_obj.name}'",
                       shift=(cam.shift_x * scale, cam.shift_y * scale))


def view_camera(eye, forward, up, fov_y_deg, clip_start, what, shift=(0.0, 0.0)):
    """A scene camera looking along `forward`; the target is placed at 100 x clip_start so that
    Sunbeam's near plane (0.01 of the eye-target distance) is Blender's Clip Start. `shift`:
    the lens shift in fractions of the frame's larger side (`camera.shift`, written when not 0)."""
    if not 0.1 < fov_y_deg < 179.0:
        raise SunbeamError(f"{what}: Focal Length: vertical field of view {fov_y_deg:.3f} deg "
                           "is outside Sunbeam's (0.1, 179)")
    if not all(math.isfinite(v) and abs(v) <= 10.0 for v in shift):
        raise SunbeamError(f"{what}: Shift: {shift[0]:.3f}, {shift[1]:.3f} is outside Sunbeam's [-10, 10]")
    target = eye + forward.normalized() * (100.0 * clip_start)
    out = {"eye": to_sunbeam(eye), "target": to_sunbeam(target), "up": to_sunbeam(up.normalized()),
           "fov_y_deg": fov_y_deg}
    if shift[0] or shift[1]:
        out["shift"] = [float(shift[0]), float(shift[1])]
    return out


# ---------------------------------------------------------------- lights

def lights(depsgraph, centre, warnings):
    """Sunbeam's directional lights for Blender's lamps.

    Intensity 1 in Sunbeam lights a white Lambertian base to radiance cos(theta), which in
    Blender is an irradiance of pi W/m^2: a sun of strength S is intensity S / pi. Point, spot
    and area lamps have no counterpart (the scene format has directional lights only): each
    becomes a directional light from the direction of the lamp seen from `centre` (the centre
    of the rendered meshes) with the irradiance it gives there (point and spot: P / (4 pi d^2);
    area: P cos / (pi d^2)), and a warning says so. The lamp's Color is the light's `color`.
    """
    out = []
    for obj in depsgraph.objects:
        if obj.type != "LIGHT":
            continue
        light = obj.data
        m = obj.matrix_world
        if light.type == "SUN":
            direction = m.to_3x3() @ Vector((0, 0, 1))
            irradiance = light.energy
        else:
            to_lamp = m.translation - centre
            d2 = max(to_lamp.length_squared, 1e-12)
            direction = to_lamp
            if light.type == "AREA":
                facing = (m.to_3x3() @ Vector((0, 0, -1))).normalized().dot(-to_lamp.normalized())
                irradiance = light.energy * max(facing, 0.0) / (math.pi * d2)
            else:
                irradiance = light.energy / (4.0 * math.pi * d2)
            warnings.append(f"Light '{obj.name}': {light.type.lower()} lamp rendered as a directional "
                            "light (Sunbeam has directional lights only)")
        if irradiance > 0.0 and direction.length > 0.0:
            entry = {"direction": to_sunbeam(direction.normalized()), "intensity": irradiance / math.pi}
            # Blender's lamp colour (scene linear): Sunbeam's `color`, which tints the light's RGB
            color = [float(c) for c in light.color]
            if color != [1.0, 1.0, 1.0]:
                entry["color"] = color
            out.append(entry)
    return out


# ---------------------------------------------------------------- world

def _srgb_to_linear(v):
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def _write_image_map(image, path, what):
    """The pixels Blender holds for `image` as a float EXR (negative and non-finite texels,
    which lossy HDRI compression leaves and Sunbeam refuses, become 0)."""
    width, height = image.size
    if width == 0 or height == 0:
        raise SunbeamError(f"{what}: image '{image.name}' has no pixels (missing file?)")
    if width != 2 * height:
        raise SunbeamError(f"{what}: image '{image.name}' is {width} x {height}; "
                           "an equirectangular map must be twice as wide as high")
    channels = image.channels
    px = array("f", bytes(4 * width * height * channels))
    image.pixels.foreach_get(px)
    decode = (_srgb_to_linear if not image.is_float and image.colorspace_settings.name == "sRGB"
              else None)
    line = width * channels

    def rows():
        for j in range(height):  # Blender's rows are bottom-up, EXR's top-down
            row = px[(height - 1 - j) * line:(height - j) * line]
            planes = []
            for c in range(3):
                plane = row[min(c, channels - 1)::channels]
                if decode:
                    plane = map(decode, plane)
                planes.append([v if 0.0 < v < _INF else 0.0 for v in plane])
            yield planes

    exr.write_rgb(path, width, height, rows())


def _constant_map(color, path):
    exr.write_rgb(path, 8, 4, ([[c] * 8 for c in color] for _ in range(4)))


def _single_link(socket):
    return socket.links[0].from_node if socket.is_linked else None


def _mapping_rotation_deg(node, what):
    """Rotation about Blender's z (degrees) of a Mapping node feeding the Environment Texture."""
    if node is None:
        return 0.0
    if node.type != "MAPPING":
        raise SunbeamError(f"{what}: Vector: only a Mapping node (rotation about Z) is supported")
    rot = node.inputs["Rotation"].default_value
    scale = node.inputs["Scale"].default_value
    if (node.inputs["Rotation"].is_linked or abs(rot[0]) > 1e-6 or abs(rot[1]) > 1e-6
            or any(abs(s - 1.0) > 1e-6 for s in scale)):
        raise SunbeamError(f"{what}: Mapping: only a rotation about Z is supported")
    angle = math.degrees(rot[2])
    return -angle if node.vector_type == "TEXTURE" else angle


def _environment_background(scene):
    """The background under a map or sky: the environment itself (`"environment"`, drawn
    along each view ray) unless Film > Transparent is on, where Blender draws none: black
    (Sunbeam's frame has no alpha)."""
    return [0.0, 0.0, 0.0] if scene.render.film_transparent else "environment"


def world(scene, tmp, warnings):
    """Sunbeam's `environment` (or None) and `background` for Blender's World (a map or sky:
    `"environment"`, or black with Film > Transparent; a plain colour: that colour).

    Blender's equirectangular lookup puts the map's centre column at +x, Sunbeam's (docs/SCENE.md)
    its first column: the same image lights the same way when Sunbeam's map is rotated by
    180 degrees plus the Mapping node's rotation about z (z is Sunbeam's y; Blender's angle from +x
    towards +y is Sunbeam's from +x towards -z, and the lookup rotation is the inverse of the map's).
    """
    w = scene.world
    what = f"World '{w.name}'" if w else "World"
    if w is None:
        return None, [0.0, 0.0, 0.0]
    if not (w.use_nodes and w.node_tree):
        color = list(w.color)
        if max(color) <= 0.0:
            return None, color
        path = os.path.join(tmp, "world.exr")
        _constant_map(color, path)
        return {"map": path, "intensity": 1.0}, color
    out = w.node_tree.get_output_node("ALL")
    bg = _single_link(out.inputs["Surface"]) if out else None
    if bg is None:
        return None, [0.0, 0.0, 0.0]
    if bg.type != "BACKGROUND":
        raise SunbeamError(f"{what}: Surface: only a Background node is supported (not {bg.name})")
    if bg.inputs["Strength"].is_linked:
        raise SunbeamError(f"{what}: Background: Strength must be a number, not a link")
    strength = bg.inputs["Strength"].default_value
    src = _single_link(bg.inputs["Color"])
    if src is None:
        color = [c * strength for c in bg.inputs["Color"].default_value[:3]]
        if max(color) <= 0.0:
            return None, color
        path = os.path.join(tmp, "world.exr")
        _constant_map(color, path)
        return {"map": path, "intensity": 1.0}, color
    if src.type == "TEX_ENVIRONMENT":
        what = f"{what}: Environment Texture '{src.name}'"
        if src.projection != "EQUIRECTANGULAR":
            raise SunbeamError(f"{what}: Projection: only Equirectangular is supported")
        if src.image is None:
            raise SunbeamError(f"{what}: Image: none set")
        rotation = 180.0 + _mapping_rotation_deg(_single_link(src.inputs["Vector"]), what)
        path = os.path.join(tmp, "world.exr")
        _write_image_map(src.image, path, what)
        rotation = (rotation + 180.0) % 360.0 - 180.0
        return ({"map": path, "rotation_deg": rotation, "intensity": strength},
                _environment_background(scene))
    if src.type == "TEX_SKY":
        what = f"{what}: Sky Texture '{src.name}'"
        if src.sky_type == "NISHITA":
            elev, azim_b = src.sun_elevation, src.sun_rotation + math.pi / 2
            sun = Vector((math.cos(elev) * math.cos(azim_b), math.cos(elev) * math.sin(azim_b),
                          math.sin(elev)))
            turbidity = 3.0
            warnings.append(f"{what}: Nishita rendered as Sunbeam's Preetham sky (turbidity 3) "
                            "at the same sun position")
        else:
            sun, turbidity = Vector(src.sun_direction).normalized(), src.turbidity
        s = to_sunbeam(sun)
        sky = {"sun_elevation_deg": math.degrees(math.asin(max(-1.0, min(1.0, s[1])))),
               "sun_azimuth_deg": math.degrees(math.atan2(s[2], s[0])),
               "turbidity": min(10.0, max(1.7, turbidity))}
        warnings.append(f"{what}: Strength scales Sunbeam's sky, which is normalised so that a "
                        "white horizontal surface has radiance 1")
        return {"sky": sky, "intensity": strength}, _environment_background(scene)
    raise SunbeamError(f"{what}: Background Color: only an Environment Texture, a Sky Texture "
                       f"or a colour is supported (not {src.name})")


# ---------------------------------------------------------------- meshes

class MeshJob:
    """One scene mesh: the object to export, its Sunbeam material (or None) and sunbeam-bake's
    source flags (None: exported without a bake)."""

    def __init__(self, obj, mat, bake_args, spine):
        self.obj, self.mat, self.bake_args, self.spine = obj, mat, bake_args, spine


def check_pack(obj, mat):
    """The absolute path of `mat`'s pack, which must exist."""
    what = f"Object '{obj.name}': material '{mat.name}' > Sunbeam > Pack"
    if not mat.sunbeam.pack:
        raise SunbeamError(f"{what}: no pack set")
    pack = bpy.path.abspath(mat.sunbeam.pack)
    if not os.path.isfile(pack):
        raise SunbeamError(f"{what}: file not found: {pack}")
    return pack


def bake_source(depsgraph, obj):
    """sunbeam-bake's source flags for `obj`, checked, and a spine's points for the curve source."""
    what = f"Object '{obj.name}': Sunbeam Orientation"
    o = obj.sunbeam
    spine = None
    if o.source == "AXIS":
        axis = Vector(o.axis)
        if axis.length == 0.0:
            raise SunbeamError(f"{what} > Axis: zero vector")
        args = ["--axis", ",".join(f"{c:.9g}" for c in to_sunbeam(axis.normalized()))]
    elif o.source == "CURVE":
        if o.curve is None:
            raise SunbeamError(f"{what} > Spine: no curve object set")
        if o.curve.type != "CURVE":
            raise SunbeamError(f"{what} > Spine: '{o.curve.name}' is not a curve object")
        curve = o.curve.evaluated_get(depsgraph)
        mesh = curve.to_mesh()
        spine = [to_sunbeam(curve.matrix_world @ v.co) for v in mesh.vertices]
        curve.to_mesh_clear()
        if len(spine) < 2:
            raise SunbeamError(f"{what} > Spine: curve '{o.curve.name}' has fewer than 2 points")
        args = ["--curve", SPINE]
    else:
        uv_layers = obj.data.uv_layers
        if len(uv_layers) <= o.uv_set:
            raise SunbeamError(f"{what} > UV Direction: the mesh has no UV map {o.uv_set} "
                               f"({len(uv_layers)} UV maps)")
        args = ["--uv-direction", o.uv_direction, "--uv-set", str(o.uv_set)]
    if o.rotate_deg:
        args += ["--rotate-deg", f"{o.rotate_deg:.9g}"]
    if o.use_scales:
        uv_layers = obj.data.uv_layers
        if len(uv_layers) <= o.uv_set:
            raise SunbeamError(f"{what} > Scales: the mesh has no UV map {o.uv_set} "
                               f"({len(uv_layers)} UV maps; scales need UVs)")
        if o.source != "UV":
            args += ["--uv-set", str(o.uv_set)]
        args += ["--scales"]
        for flag, name in SCALE_FLAGS:
            value = getattr(o, name)
            args += [flag, str(value) if isinstance(value, int) else _float32_text(value)]
    return args, spine


# sunbeam-bake's scale flags and the object settings that give them (properties.py)
SCALE_FLAGS = (("--scale-rows", "scale_rows"), ("--scale-length", "scale_length"),
               ("--scale-overlap", "scale_overlap"), ("--scale-dome", "scale_dome"),
               ("--scale-keel", "scale_keel"), ("--scale-tilt", "scale_tilt"), ("--scale-tilt-jitter", "scale_tilt_jitter"),
               ("--scale-ridge-jitter", "scale_ridge_jitter"), ("--scale-texels", "scale_texels"),
               ("--scale-seed", "scale_seed"))


def _float32_text(value):
    """The shortest decimal that reads back as the same float32 (Blender's FloatProperty): a
    limit such as 0.6 is written "0.6", not "0.600000024", which the tool's range refuses."""
    stored = struct.unpack("<f", struct.pack("<f", value))[0]
    for digits in range(1, 10):
        near = float(f"{stored:.{digits}g}")
        if struct.unpack("<f", struct.pack("<f", near))[0] == stored:
            return repr(near)
    return repr(stored)


def mesh_jobs(depsgraph, warnings):
    """The scene's meshes, checked: every Sunbeam material's pack exists, every source is usable."""
    jobs = []
    for obj in depsgraph.objects:
        if obj.type != "MESH":
            if obj.type not in ("LIGHT", "CAMERA", "EMPTY", "CURVE"):
                warnings.append(f"Object '{obj.name}': {obj.type.lower()} objects are not exported")
            continue
        orig = obj.original
        mat = sunbeam_material(orig)
        if mat is None:
            jobs.append(MeshJob(orig, None, None, None))
        else:
            check_pack(orig, mat)
            args, spine = bake_source(depsgraph, orig)
            jobs.append(MeshJob(orig, mat, args, spine))
    if not jobs:
        raise SunbeamError("Scene: no mesh objects to render")
    return jobs


def _export_glb(depsgraph, obj, path):
    """`obj` alone as GLB by Blender's glTF exporter (modifiers applied, +Y up, UVs kept).

    The scene and view layer come from `depsgraph`, not from bpy.context, which a final
    render's thread may not have: they are passed to the exporter by a context override, and
    the selection it exports is set (and restored) on that view layer. The exporter needs a
    window (it sets the window's scene) and the active object, which the job thread of an F12
    render in Blender's UI lacks, so there it runs on the main thread (a timer) and the render
    waits for it."""
    scene, view_layer = depsgraph.scene, depsgraph.view_layer

    def export():
        selected = [o for o in view_layer.objects if o.select_get(view_layer=view_layer)]
        try:
            for o in selected:
                o.select_set(False, view_layer=view_layer)
            obj.select_set(True, view_layer=view_layer)
            try:
                with bpy.context.temp_override(scene=scene, view_layer=view_layer):
                    bpy.ops.export_scene.gltf(
                        filepath=path, export_format="GLB", use_selection=True, export_apply=True,
                        export_yup=True, export_texcoords=True, export_normals=True,
                        export_materials="NONE", export_cameras=False, export_lights=False,
                        export_animations=False, export_skins=False, export_morph=False,
                        export_extras=False, will_save_settings=False)
            except RuntimeError as e:
                raise SunbeamError(f"Object '{obj.name}': glTF export: {e}") from None
        finally:
            obj.select_set(False, view_layer=view_layer)
            for o in selected:
                o.select_set(True, view_layer=view_layer)

    if threading.current_thread() is threading.main_thread() or bpy.app.background:
        export()
    else:
        _on_main_thread(export)
    if not os.path.isfile(path):
        raise SunbeamError(f"Object '{obj.name}': the glTF exporter wrote nothing")


def _on_main_thread(fn, timeout_s=600.0):
    """Run `fn` in Blender's main thread (a one-shot timer) and wait for it; its exception is
    raised here."""
    done, box = threading.Event(), {}

    def run():
        try:
            fn()
        except BaseException as e:  # noqa: B036 - handed to the waiting thread
            box["error"] = e
        done.set()
        return None

    bpy.app.timers.register(run, first_interval=0.0)
    if not done.wait(timeout_s):
        raise SunbeamError(f"the glTF export did not run on Blender's main thread within {timeout_s:.0f} s")
    if "error" in box:
        raise box["error"]


def bake(depsgraph, job, tmp, index, cancelled, out=None, warnings=None):
    """Export `job`'s object into `tmp` and, with bake flags, bake its orientation field (into
    `out` if given: sunbeam-bake writes atomically, and paths it writes are relative to the
    output): the GLB's path. The bake's own warnings (its --json report's, e.g. a UV layout
    that does not fit the scales) go to `warnings`."""
    exported = os.path.join(tmp, f"mesh{index}.glb")
    _export_glb(depsgraph, job.obj, exported)
    if job.bake_args is None:
        return exported
    args = list(job.bake_args)
    if job.spine is not None:
        spine = os.path.join(tmp, f"spine{index}.json")
        with open(spine, "w") as f:
            json.dump({"points": job.spine}, f)
        args[args.index(SPINE)] = spine
    baked = out or os.path.join(tmp, f"mesh{index}-baked.glb")
    try:
        report = tools.run("sunbeam-bake", [exported, "-o", baked, "-q", "--json", *args], cancelled)
    except SunbeamError as e:
        raise SunbeamError(f"Object '{job.obj.name}': Sunbeam Orientation: {e}") from None
    if warnings is not None:
        try:
            found = json.loads(report).get("warnings", [])
        except ValueError:
            found = []
        warnings.extend(f"Object '{job.obj.name}': sunbeam-bake: {w}" for w in found)
    return baked


def mesh_entry(job, glb):
    """docs/SCENE.md meshes[] for one exported mesh."""
    if job.mat is None:
        return {"mesh": glb, "base_color": _base_color(job.obj)}
    s = job.mat.sunbeam
    entry = {"mesh": glb, "pack": bpy.path.abspath(s.pack), "base_color": list(s.base_color),
             "diffuse_weight": s.diffuse_weight, "masking": s.masking, "ior": s.ior,
             "reflectance": s.reflectance}
    if s.use_rms_slope:
        entry["rms_slope"] = list(s.rms_slope)
    return entry


def bounds_centre(jobs):
    """Centre of the world bounding box of the jobs' objects (where lamps are seen from)."""
    corners = [o.matrix_world @ Vector(c) for o in (j.obj for j in jobs) for c in o.bound_box]
    lo = Vector([min(c[i] for c in corners) for i in range(3)])
    hi = Vector([max(c[i] for c in corners) for i in range(3)])
    return (lo + hi) / 2


def check_tools(jobs, renderer):
    """Every tool the render needs, found before anything runs."""
    try:
        tools.find_tool(renderer)
    except SunbeamError as e:
        raise SunbeamError(f"Render: {e}") from None
    for job in jobs:
        if job.mat is not None:
            try:
                tools.find_tool("sunbeam-bake")
            except SunbeamError as e:
                raise SunbeamError(f"Object '{job.obj.name}': Sunbeam Orientation: {e}") from None
            break


def build_scene(depsgraph, tmp, renderer, cancelled, progress, warnings):
    """Check, then export and bake into `tmp`: the scene document without camera and size.
    `progress(fraction, text)` is told each mesh."""
    jobs = mesh_jobs(depsgraph, warnings)
    check_tools(jobs, renderer)
    environment, background = world(depsgraph.scene, tmp, warnings)
    doc = {"lights": lights(depsgraph, bounds_centre(jobs), warnings), "meshes": [],
           "exposure": 0, "background": background}
    if environment:
        doc["environment"] = environment
    for i, job in enumerate(jobs):
        progress(0.5 * i / len(jobs), f"Exporting and baking {job.obj.name}")
        doc["meshes"].append(mesh_entry(job, bake(depsgraph, job, tmp, i, cancelled,
                                                  warnings=warnings)))
    return doc


def save_scene(doc, camera, size, path):
    """`doc` seen by `camera` at `size` as scene JSON at `path` (a temporary name, then a rename)."""
    with open(path + ".part", "w") as f:
        json.dump({**doc, "camera": camera, "size": list(size)}, f, indent=1)
    os.replace(path + ".part", path)
    return path
