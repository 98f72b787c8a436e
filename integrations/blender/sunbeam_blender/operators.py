"""The pipeline steps as Blender operators: an AFM scan to a pack (sunbeam-import, then
sunbeam-pack --response), a pack to a Sunbeam material on the active object, and the active
object's orientation field baked into a GLB (sunbeam-bake) for use outside Blender.

Each runs the tools in a temporary folder and moves the finished files into place only when
every step succeeded, so a failure leaves nothing half-written beside the user's files.
"""

import json
import os
import shutil
import tempfile
from pathlib import Path

import bpy
from bpy.props import BoolProperty, EnumProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import export, tools
from .tools import SunbeamError

_channel_items = {}  # scan path -> enum items (Blender needs the strings kept alive)


def _channels(op, _context):
    """The channels `sunbeam-import --list` reports for the chosen file."""
    path = bpy.path.abspath(op.filepath)
    if path not in _channel_items:
        items = [("DEFAULT", "Default", "The first height channel")]
        if os.path.isfile(path):
            try:
                listing = json.loads(tools.run("sunbeam-import", [path, "--list", "--json"]))
                items += [(str(c["index"]), f'{c["index"]}: {c["name"]}',
                           f'{c["width"]} x {c["height"]} px, z unit {c["z_unit"]}'
                           + (", height" if c["is_height"] else ""))
                          for c in listing["channels"]]
            except SunbeamError:
                pass  # e.g. an image without calibration: only the default; the import says why
        _channel_items[path] = items
    return _channel_items[path]


def _commit(tmp, names, folder):
    """Move the finished `names` from `tmp` into `folder` (same file system: atomic renames)."""
    for name in names:
        os.replace(os.path.join(tmp, name), os.path.join(folder, name))


class SUNBEAM_OT_import_scan(bpy.types.Operator, ImportHelper):
    """Import an AFM scan as a Sunbeam pack (sunbeam-import, sunbeam-pack --response)"""

    bl_idname = "sunbeam.import_scan"
    bl_label = "Import AFM Scan as Sunbeam Pack"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*", options={"HIDDEN"})
    channel: EnumProperty(name="Channel", items=_channels,
                          description="Channel of the scan (sunbeam-import --list)")
    level: EnumProperty(name="Levelling", default="plane",
                        items=[("none", "None", "No background levelling"),
                               ("plane", "Plane", "Gwyddion's Plane Level"),
                               ("poly", "Polynomial", "Polynomial of the degree below")])
    poly_degree: IntProperty(name="Degree", min=1, max=8, default=2)
    align_rows: EnumProperty(name="Align Rows", default="none",
                             items=[("none", "None", ""), ("median", "Median", ""),
                                    ("median-diff", "Median of Differences", "")])
    fill_nonfinite: BoolProperty(name="Fill Non-finite", default=False)
    remove_scars: BoolProperty(name="Remove Scars", default=False)
    zero_mean: BoolProperty(name="Zero Mean", default=True)
    pixel_size: StringProperty(name="Pixel Size", default="",
                               description="Calibration of plain images, e.g. 65nm (empty: the file's)")
    z_range: StringProperty(name="Z Range", default="",
                            description="Height of the full grey range of plain images, e.g. 375nm")
    output_folder: StringProperty(name="Output Folder", subtype="DIR_PATH", default="",
                                  description="Where the pack goes (empty: beside the scan)")
    assign: BoolProperty(name="Assign to Active Object", default=True)

    def execute(self, context):
        scan = bpy.path.abspath(self.filepath)
        folder = bpy.path.abspath(self.output_folder) if self.output_folder else os.path.dirname(scan)
        stem = Path(scan).stem
        args = []
        if self.channel != "DEFAULT":
            args += ["--channel", self.channel]
        if self.level != "none":
            args += ["--level", "plane" if self.level == "plane" else f"poly:{self.poly_degree}"]
        args += ["--align-rows", self.align_rows]
        for flag, on in (("--fill-nonfinite", self.fill_nonfinite),
                         ("--remove-scars", self.remove_scars), ("--zero-mean", self.zero_mean)):
            if on:
                args.append(flag)
        if self.pixel_size:
            args += ["--pixel-size", self.pixel_size]
        if self.z_range:
            args += ["--z-range", self.z_range]
        names = [f"{stem}.exr", f"{stem}.ktx2", f"{stem}.response.ktx2"]
        try:
            if not os.path.isdir(folder):
                raise SunbeamError(f"Output Folder: not a folder: {folder}")
            tmp = tempfile.mkdtemp(prefix=".sunbeam-import-", dir=folder)
            try:
                height = os.path.join(tmp, names[0])
                tools.run("sunbeam-import", [scan, "-o", height, "-q", *args])
                tools.run("sunbeam-pack", [height, "-o", os.path.join(tmp, names[1]), "-q", "--response"])
                _commit(tmp, names, folder)
            finally:
                shutil.rmtree(tmp, ignore_errors=True)
        except (SunbeamError, OSError) as e:
            self.report({"ERROR"}, f"Import '{os.path.basename(scan)}': {e}")
            return {"CANCELLED"}
        pack = os.path.join(folder, names[1])
        self.report({"INFO"}, f"Wrote {pack}")
        if self.assign and context.active_object and context.active_object.type == "MESH":
            assign_pack(context.active_object, pack)
        return {"FINISHED"}


def assign_pack(obj, pack):
    """A new Sunbeam material with `pack` in `obj`'s active slot (a new slot if it has none)."""
    mat = bpy.data.materials.new(f"Sunbeam {Path(pack).stem}")
    mat.sunbeam.enabled = True
    mat.sunbeam.pack = pack
    mat.diffuse_color = (*mat.sunbeam.base_color, 1.0)
    if obj.material_slots:
        obj.material_slots[obj.active_material_index].material = mat
    else:
        obj.data.materials.append(mat)
    return mat


class SUNBEAM_OT_assign_pack(bpy.types.Operator, ImportHelper):
    """Give the active object a Sunbeam material with the chosen pack"""

    bl_idname = "sunbeam.assign_pack"
    bl_label = "Assign Sunbeam Pack"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.ktx2;*.exr", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def execute(self, context):
        obj = context.active_object
        pack = bpy.path.abspath(self.filepath)
        if not os.path.isfile(pack):
            self.report({"ERROR"}, f"Object '{obj.name}': Sunbeam > Pack: file not found: {pack}")
            return {"CANCELLED"}
        assign_pack(obj, pack)
        return {"FINISHED"}


class SUNBEAM_OT_bake_orientation(bpy.types.Operator, ExportHelper):
    """Bake the active object's orientation field (sunbeam-bake) into a GLB; with a Sunbeam
    material the GLB also names its pack (for three.js and other engines)"""

    bl_idname = "sunbeam.bake_orientation"
    bl_label = "Bake Sunbeam Orientation"

    filename_ext = ".glb"
    filter_glob: StringProperty(default="*.glb", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def execute(self, context):
        obj = context.active_object
        out = bpy.path.abspath(self.filepath)
        try:
            depsgraph = context.evaluated_depsgraph_get()
            args, spine = export.bake_source(depsgraph, obj)
            mat = export.sunbeam_material(obj)
            if mat is not None:
                args += ["--pack", export.check_pack(obj, mat),
                         "--diffuse-weight", f"{mat.sunbeam.diffuse_weight:.9g}"]
            job = export.MeshJob(obj, mat, args, spine)
            tools.find_tool("sunbeam-bake")
            warnings = []
            with tempfile.TemporaryDirectory(prefix="sunbeam-bake-") as tmp:
                export.bake(depsgraph, job, tmp, 0, lambda: False, out, warnings)
        except (SunbeamError, OSError) as e:
            self.report({"ERROR"}, str(e) if str(e).startswith("Object") else f"Object '{obj.name}': {e}")
            return {"CANCELLED"}
        for w in warnings:
            self.report({"WARNING"}, w)
        self.report({"INFO"}, f"Wrote {out}")
        return {"FINISHED"}


classes = (SUNBEAM_OT_import_scan, SUNBEAM_OT_assign_pack, SUNBEAM_OT_bake_orientation)


def menu_import(self, _context):
    self.layout.operator(SUNBEAM_OT_import_scan.bl_idname, text="AFM Scan as Sunbeam Pack")


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
