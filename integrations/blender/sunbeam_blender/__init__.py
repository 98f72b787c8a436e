"""Sunbeam for Blender: structural colour from AFM scans of snake skin, rendered by the Sunbeam
tools from inside Blender (docs/BLENDER.md).

Blender's engines cannot shade Sunbeam's diffraction material, so the add-on adds a render
engine that translates the scene and runs the tools, plus operators for the pipeline steps.
It imports only Blender's bundled Python (bpy and the standard library): the tools do the work.
"""

bl_info = {
    "name": "Sunbeam",
    "author": "Sunbeam",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "Render Engine > Sunbeam; File > Import > AFM Scan as Sunbeam Pack; "
                "Material and Object Properties > Sunbeam",
    "description": "Diffraction colour of snake skin from AFM scans, rendered by the Sunbeam tools",
    "category": "Render",
}

from . import engine, operators, properties, ui  # noqa: E402 (bl_info must come first)

_modules = (properties, operators, ui, engine)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
