# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender add-on: imports the surface sequence of a karst run (fluid_surface_NNNN.ply and
porous_surface_NNNN.ply) as one object per part and frame, shown only on its own frame, with a
water material (glass-like, tinted by the M29 vertex colour) and a rock material (vertex colour:
wet is darker).

As an add-on: Edit > Preferences > Add-ons > Install..., pick this file, enable "karst", then
File > Import > karst run (folder). From the command line (Blender 3.4 or later):

    blender --background --python tools/blender/karst_import.py -- OUT_DIR [--save FILE.blend]
"""
import glob
import os
import re
import sys

import bpy

bl_info = {
    "name": "karst",
    "author": "karst developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > karst run (folder)",
    "description": "Import the fluid and porous surfaces of a karst run",
    "category": "Import-Export",
}


def vertex_colour_material(name, water):
    """A Principled material whose base colour is the mesh's vertex colour attribute "Col"."""
    material = bpy.data.materials.get(name)
    if material:
        return material
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    bsdf = nodes.get("Principled BSDF")
    colour = nodes.new("ShaderNodeVertexColor")
    colour.layer_name = "Col"
    material.node_tree.links.new(colour.outputs["Color"], bsdf.inputs["Base Color"])
    if water:
        bsdf.inputs["Transmission"].default_value = 1.0
        bsdf.inputs["Roughness"].default_value = 0.02
        bsdf.inputs["IOR"].default_value = 1.33
    else:
        bsdf.inputs["Roughness"].default_value = 0.8
    return material


def import_ply(path):
    """The mesh object of a PLY file (the importer's name changed in Blender 3.6)."""
    before = set(bpy.data.objects)
    if bpy.app.version >= (3, 6, 0):
        bpy.ops.wm.ply_import(filepath=path)
    else:
        bpy.ops.import_mesh.ply(filepath=path)
    new = [o for o in bpy.data.objects if o not in before]
    if len(new) != 1:
        raise RuntimeError("importing %s made %d objects" % (path, len(new)))
    return new[0]


def show_only_on(obj, frame):
    """Keyframes the object visible on `frame` alone."""
    for f, hidden in ((frame - 1, True), (frame, False), (frame + 1, True)):
        if f < 0:
            continue
        obj.hide_render = obj.hide_viewport = hidden
        obj.keyframe_insert("hide_render", frame=f)
        obj.keyframe_insert("hide_viewport", frame=f)


def import_run(folder):
    """Imports every surface frame of `folder`; returns the number of frames."""
    frames = 0
    collection = bpy.data.collections.new("karst " + os.path.basename(os.path.normpath(folder)))
    bpy.context.scene.collection.children.link(collection)
    for part, water in (("fluid_surface", True), ("porous_surface", False)):
        material = vertex_colour_material("karst " + ("water" if water else "rock"), water)
        for path in sorted(glob.glob(os.path.join(folder, part + "_*.ply"))):
            frame = int(re.search(r"_(\d+)\.ply$", path).group(1))
            obj = import_ply(path)
            for c in obj.users_collection:
                c.objects.unlink(obj)
            collection.objects.link(obj)
            obj.data.materials.append(material)
            show_only_on(obj, frame)
            frames = max(frames, frame + 1)
    if frames == 0:
        raise RuntimeError("no fluid_surface_NNNN.ply or porous_surface_NNNN.ply in " + folder)
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = 0, frames - 1
    return frames


class ImportKarstRun(bpy.types.Operator):
    """Import the surfaces of a karst run folder"""

    bl_idname = "import_scene.karst_run"
    bl_label = "Import karst run"
    directory: bpy.props.StringProperty(subtype="DIR_PATH")

    def execute(self, context):
        frames = import_run(self.directory)
        self.report({"INFO"}, "karst: imported %d frames" % frames)
        return {"FINISHED"}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}


def menu_entry(self, context):
    self.layout.operator(ImportKarstRun.bl_idname, text="karst run (folder)")


def register():
    bpy.utils.register_class(ImportKarstRun)
    bpy.types.TOPBAR_MT_file_import.append(menu_entry)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_entry)
    bpy.utils.unregister_class(ImportKarstRun)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    if not args:
        sys.exit("usage: blender --background --python karst_import.py -- OUT_DIR [--save FILE]")
    count = import_run(args[0])
    print("karst: imported %d frames from %s" % (count, args[0]))
    if "--save" in args:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args[args.index("--save") + 1]))
