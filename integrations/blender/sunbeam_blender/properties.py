"""The add-on's settings stored in .blend files: a Sunbeam material (docs/SCENE.md meshes[]),
an object's orientation source (sunbeam-bake's sources), the engine's render settings, and
the add-on preference for where the tools are.

They are plain properties on Blender's own data blocks so that they are saved, copied, linked
and undone with the material, object or scene they belong to.
"""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)


class SunbeamMaterialSettings(bpy.types.PropertyGroup):
    """One scene mesh's material: the fields of docs/SCENE.md meshes[]."""

    enabled: BoolProperty(name="Sunbeam Material", default=False,
                          description="Render objects using this material with a Sunbeam pack")
    pack: StringProperty(name="Pack", subtype="FILE_PATH",
                         description="Diffraction pack (.ktx2 or .exr from sunbeam-pack --response)")
    base_color: FloatVectorProperty(name="Base Color", subtype="COLOR", size=3, min=0.0, max=1.0,
                                    default=(0.05, 0.05, 0.05),
                                    description="Diffuse base colour, linear sRGB (meshes[].base_color)")
    diffuse_weight: FloatProperty(name="Diffuse Weight", min=0.0, max=1.0, default=0.2,
                                  description="Weight of the base against the diffraction (meshes[].diffuse_weight)")
    masking: EnumProperty(name="Masking", default="off",
                          items=[("off", "Off", "No shadowing or masking by the relief"),
                                 ("smith", "Smith", "Smith masking with the pack's rms slopes "
                                  "(use under an environment)")],
                          description="Shadowing and masking on the diffraction (meshes[].masking)")
    ior: FloatProperty(name="IOR", min=1.0001, max=4.0, default=1.5, precision=3,
                       description="The skin's refractive index (meshes[].ior)")
    reflectance: EnumProperty(name="Reflectance", default="absolute",
                              items=[("absolute", "Absolute", "Physical reflectance: F(0) head-on"),
                                     ("relative", "Relative", "Divided by F(0), the thesis' normalisation")],
                              description="meshes[].reflectance")
    use_rms_slope: BoolProperty(name="Override RMS Slope", default=False,
                                description="Give the rms slopes instead of the pack's (meshes[].rms_slope)")
    rms_slope: FloatVectorProperty(name="RMS Slope", size=2, min=0.0, default=(0.1, 0.1),
                                   description="RMS slopes along t and along b")


class SunbeamObjectSettings(bpy.types.PropertyGroup):
    """Where the orientation field of an object comes from (sunbeam-bake's source flags)."""

    source: EnumProperty(name="Orientation", default="AXIS",
                         items=[("AXIS", "Axis", "A world direction projected onto each tangent plane (--axis)"),
                                ("CURVE", "Spine Curve", "The tangent of a curve object (--curve)"),
                                ("UV", "UV Direction", "The direction of increasing u or v (--uv-direction)")])
    axis: FloatVectorProperty(name="Axis", subtype="DIRECTION", size=3, default=(1.0, 0.0, 0.0),
                              description="World direction (Blender axes) of the ridges")
    # No poll callback limiting the choice to curves: with one, Blender as a Python module
    # (bpy 4.2, the tests) crashes at exit. bake_source() refuses other object types instead.
    curve: PointerProperty(name="Spine", type=bpy.types.Object,
                           description="Curve object whose tangent gives the direction")
    uv_direction: EnumProperty(name="UV Direction", default="u",
                               items=[("u", "U", "Increasing u"), ("v", "V", "Increasing v")])
    uv_set: IntProperty(name="UV Map Index", min=0, default=0,
                        description="Which UV map (glTF TEXCOORD_N) the UV source and the "
                        "scales read (--uv-set)")
    rotate_deg: FloatProperty(name="Rotate", default=0.0, subtype="NONE",
                              description="Extra rotation about the normal, degrees, "
                              "counter-clockwise seen from outside (--rotate-deg)")
    # sunbeam-bake --scales (docs/BAKE.md "Scales"): the same ranges and defaults as the tool's,
    # as hard limits, so Blender clamps what the tool would refuse. The seed is a u64 in the
    # tool; Blender's integers are 32-bit.
    use_scales: BoolProperty(name="Scales", default=False,
                             description="Bake scales: a normal map and a ridge-orientation map "
                             "in the GLB (--scales); needs UVs, u along the body, v around it")
    scale_rows: IntProperty(name="Rows", min=3, max=200, default=20,
                            description="Scale rows around the body, one turn of v (--scale-rows)")
    scale_length: FloatProperty(name="Length", min=0.25, max=4.0, default=1.0,
                                description="Scale length along the body, in scale widths "
                                "(--scale-length)")
    scale_overlap: FloatProperty(name="Overlap", min=0.0, max=0.6, default=0.3,
                                 description="Overlap of a scale's free edge over the scale behind "
                                 "it, in scale lengths (--scale-overlap)")
    scale_dome: FloatProperty(name="Dome", min=0.0, max=0.3, default=0.06, precision=3,
                              description="Dome height of a scale, in scale widths (--scale-dome)")
    scale_keel: FloatProperty(name="Keel", min=0.0, max=0.1, default=0.0, precision=3,
                              description="Keel height of a scale, a ridge along its midline, in "
                              "scale widths; 0: smooth (--scale-keel)")
    scale_tilt: FloatProperty(name="Tilt", min=-30.0, max=30.0, default=6.0,
                              description="Tilt of the free edge, degrees: the scale's normal turns "
                              "toward the head (--scale-tilt)")
    scale_tilt_jitter: FloatProperty(name="Tilt Jitter", min=0.0, max=20.0, default=4.0,
                                     description="Per-scale jitter of the tilt, uniform in +-degrees "
                                     "(--scale-tilt-jitter)")
    scale_ridge_jitter: FloatProperty(name="Ridge Jitter", min=0.0, max=45.0, default=6.0,
                                      description="Per-scale jitter of the ridge angle about the "
                                      "normal, uniform in +-degrees (--scale-ridge-jitter)")
    scale_texels: IntProperty(name="Texels per Scale", min=4, max=256, default=32,
                              description="Texels across one scale width, reduced when a side would "
                              "pass 8192 (--scale-texels)")
    scale_seed: IntProperty(name="Seed", min=0, default=1,
                            description="Seed of the per-scale jitter (--scale-seed)")


class SunbeamRenderSettings(bpy.types.PropertyGroup):
    """The engine's settings in Render Properties."""

    samples: IntProperty(name="Samples", min=1, max=16384, default=16,
                         description="Samples per pixel of the final render (sunbeam-eval render "
                         "--samples): a square number, 1, 4, 9, 16, ...")
    preview_frames: IntProperty(name="Viewport Frames", min=1, max=256, default=8,
                                description="Progressive frames of the viewport preview "
                                "(sunbeam-play --frames)")


class SunbeamPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    binaries_folder: StringProperty(
        name="Binaries Folder", subtype="DIR_PATH", default="",
        description="Folder with sunbeam-import, -pack, -bake, -eval, -play; empty: PATH, "
        "then the project's target/release")

    def draw(self, _context):
        self.layout.prop(self, "binaries_folder")


classes = (SunbeamMaterialSettings, SunbeamObjectSettings, SunbeamRenderSettings,
           SunbeamPreferences)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Material.sunbeam = PointerProperty(type=SunbeamMaterialSettings)
    bpy.types.Object.sunbeam = PointerProperty(type=SunbeamObjectSettings)
    bpy.types.Scene.sunbeam = PointerProperty(type=SunbeamRenderSettings)


def unregister():
    del bpy.types.Scene.sunbeam
    del bpy.types.Object.sunbeam
    del bpy.types.Material.sunbeam
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
