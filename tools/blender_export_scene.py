"""Builds a small scene in Blender and exports it with Blender's own glTF
exporter: scenes/models/blender_room.glb, the scene that
scenes/blender_room.toml writes by hand and that
crates/airlight/tests/blender.rs renders both ways.

The scene (Blender is Z-up; the exporter turns (x, y, z) into glTF's Y-up
(x, z, −y)):
- a camera at (0, −6, 3) aimed at (0, 0, 0.5), 40° vertical field of view,
  160×120;
- a 200 W point light at (1.5, −1, 3) (radius 0: a true point);
- a 1 m square at height 2.5 facing down, emitting white at strength 4;
- a 6 m floor at z = 0 with an 8×8 image texture (linear interpolation,
  repeat), colours set below in sRGB codes;
- a 1 m diffuse box (base colour 0.2, 0.5, 0.8) standing at (1, 0.5).
All materials are Principled BSDFs with roughness 1, metallic 0 and
specular IOR level 0 (diffuse only).

    pip install bpy           # in a Python 3.11 virtual environment (bpy 5.0)
    python tools/blender_export_scene.py [--out scenes/models] [--cycles ref.exr --spp 1024]

With --cycles it also renders the scene in Cycles, direct light only
(max_bounces 0, box filter 1 pixel wide, black world) to an OpenEXR file,
as a reference for `airlight render scenes/blender_room.toml`.
"""

import argparse
import math
import os

import bpy
from mathutils import Vector

# The floor texture: 8×8 sRGB codes; texel (i, j) is column i, row j from
# the top. A checker of 2×2 blocks, its top-left quarter in other colours,
# so that a flipped or turned image would show.
PALETTE = [(230, 200, 150), (60, 90, 40), (200, 60, 50), (240, 240, 240)]


def texel(i, j):
    return PALETTE[(i // 2 + j // 2) % 2 + (2 if i < 4 and j < 4 else 0)]


def diffuse_material(name, colour=None, image=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    if colour is not None:
        bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    if image is not None:
        node = m.node_tree.nodes.new("ShaderNodeTexImage")
        node.image = image
        node.interpolation = "Linear"
        node.extension = "REPEAT"
        m.node_tree.links.new(node.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def build(out_dir):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 160, 120
    scene.render.resolution_percentage = 100

    # The floor's texture, saved as PNG beside the model (the TOML reads it).
    image = bpy.data.images.new("floor_texture", 8, 8, alpha=False)
    pixels = []
    for row in range(8):
        # Blender stores rows from the bottom; row 0 of the image is the top.
        j = 7 - row
        for i in range(8):
            pixels.extend([c / 255.0 for c in texel(i, j)] + [1.0])
    image.pixels = pixels
    image.filepath_raw = os.path.join(out_dir, "blender_floor.png")
    image.file_format = "PNG"
    image.save()

    bpy.ops.mesh.primitive_plane_add(size=6, location=(0, 0, 0))
    floor = bpy.context.object
    floor.name = "floor"
    floor.data.materials.append(diffuse_material("floor", image=image))

    bpy.ops.mesh.primitive_cube_add(size=1, location=(1, 0.5, 0.5))
    box = bpy.context.object
    box.name = "box"
    box.data.materials.append(diffuse_material("box", colour=(0.2, 0.5, 0.8)))

    bpy.ops.mesh.primitive_plane_add(size=1, location=(-0.5, 0.5, 2.5), rotation=(math.pi, 0, 0))
    lamp = bpy.context.object
    lamp.name = "lamp"
    glow = diffuse_material("lamp", colour=(0.0, 0.0, 0.0))
    bsdf = glow.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Emission Color"].default_value = (1, 1, 1, 1)
    bsdf.inputs["Emission Strength"].default_value = 4.0
    lamp.data.materials.append(glow)

    light_data = bpy.data.lights.new("bulb", type="POINT")
    light_data.energy = 200.0
    light_data.shadow_soft_size = 0.0
    bulb = bpy.data.objects.new("bulb", light_data)
    bulb.location = (1.5, -1, 3)
    scene.collection.objects.link(bulb)

    camera_data = bpy.data.cameras.new("eye")
    camera_data.sensor_fit = "VERTICAL"
    camera_data.angle_y = math.radians(40)
    camera = bpy.data.objects.new("eye", camera_data)
    camera.location = (0, -6, 3)
    camera.rotation_euler = (Vector((0, 0, 0.5)) - camera.location).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(camera)
    scene.camera = camera

    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "scenes", "models"))
    parser.add_argument("--cycles", help="also render in Cycles to this OpenEXR file")
    parser.add_argument("--spp", type=int, default=1024)
    args = parser.parse_args()
    out_dir = os.path.abspath(args.out)
    scene = build(out_dir)
    bpy.ops.export_scene.gltf(
        filepath=os.path.join(out_dir, "blender_room.glb"),
        export_format="GLB",
        export_lights=True,
        export_cameras=True,
        export_yup=True,
        export_apply=True,
    )
    if args.cycles:
        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = args.spp
        scene.cycles.use_denoising = False
        scene.cycles.max_bounces = 0
        scene.cycles.pixel_filter_type = "BOX"
        scene.cycles.filter_width = 1.0
        scene.cycles.seed = 0
        scene.view_settings.view_transform = "Standard"
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.filepath = os.path.abspath(args.cycles)
        bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    main()
