"""The add-on's panels: the Sunbeam material (Material Properties), the orientation source
(Object Properties) and the engine's settings (Render Properties)."""

import bpy


class SUNBEAM_PT_material(bpy.types.Panel):
    bl_label = "Sunbeam"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.material is not None

    def draw_header(self, context):
        self.layout.prop(context.material.sunbeam, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.material.sunbeam
        layout.active = s.enabled
        layout.prop(s, "pack")
        layout.prop(s, "base_color")
        layout.prop(s, "diffuse_weight")
        layout.prop(s, "masking")
        layout.prop(s, "ior")
        layout.prop(s, "reflectance")
        layout.prop(s, "use_rms_slope")
        row = layout.row()
        row.active = s.use_rms_slope
        row.prop(s, "rms_slope")
        layout.operator("sunbeam.assign_pack", text="Assign New Pack...", icon="FILE_FOLDER")


class SUNBEAM_PT_orientation(bpy.types.Panel):
    bl_label = "Sunbeam Orientation"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        o = context.object.sunbeam
        layout.prop(o, "source")
        if o.source == "AXIS":
            layout.prop(o, "axis")
        elif o.source == "CURVE":
            layout.prop(o, "curve")
        else:
            layout.prop(o, "uv_direction")
            layout.prop(o, "uv_set")
        layout.prop(o, "rotate_deg")
        layout.operator("sunbeam.bake_orientation", text="Bake to GLB...", icon="EXPORT")


class SUNBEAM_PT_orientation_scales(bpy.types.Panel):
    """sunbeam-bake --scales: a sub-panel of the orientation, ticked in its header."""

    bl_label = "Scales"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"
    bl_parent_id = "SUNBEAM_PT_orientation"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw_header(self, context):
        self.layout.prop(context.object.sunbeam, "use_scales", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        o = context.object.sunbeam
        layout.active = o.use_scales
        if o.source != "UV":
            layout.prop(o, "uv_set")
        for name in ("scale_rows", "scale_length", "scale_overlap", "scale_dome", "scale_keel",
                     "scale_tilt", "scale_tilt_jitter", "scale_ridge_jitter", "scale_texels",
                     "scale_seed"):
            layout.prop(o, name)


class SUNBEAM_PT_render(bpy.types.Panel):
    bl_label = "Sunbeam"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    @classmethod
    def poll(cls, context):
        return context.engine == "SUNBEAM"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(context.scene.sunbeam, "samples")
        layout.prop(context.scene.sunbeam, "preview_frames")
        layout.operator("sunbeam.import_scan", text="Import AFM Scan...", icon="IMPORT")


classes = (SUNBEAM_PT_material, SUNBEAM_PT_orientation, SUNBEAM_PT_orientation_scales,
           SUNBEAM_PT_render)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
