# Makes the Blender test files of tests/light_units.rs: two scenes exported with Blender's glTF
# exporter (default settings, punctual lights on) and rendered by Cycles with the Standard view
# transform, so Mirador's images of the exported files can be compared with Blender's own.
#
#   blender -b --python tests/data/blender/make.py -- tests/data/blender
#
# Debian 12's `blender` package (3.4, with python3-numpy for the exporter) runs it headless. Both
# scenes keep the start-up file's world, a uniform grey of 0.0509: glTF carries no world, and
# Mirador gives a bare model that brings its own lights that same world (ambient and background).
# Denoising is off (Debian's build has no OpenImageDenoise); 256 samples keep the noise low.
import math
import os
import sys

import bpy

out = sys.argv[sys.argv.index("--") + 1]
WIDTH, HEIGHT = 320, 240


def setup(scene):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 256
    scene.cycles.use_denoising = False
    scene.cycles.seed = 1
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    if scene.world is None:
        world = bpy.data.worlds.new("World")
        world.use_nodes = True
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.0509, 0.0509, 0.0509, 1)
        scene.world = world


def material(name, colour, metallic=0.0, roughness=0.5, transmission=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (*colour, 1)
    b.inputs["Metallic"].default_value = metallic
    b.inputs["Roughness"].default_value = roughness
    b.inputs["Transmission"].default_value = transmission
    return m


def export_and_render(name):
    scene = bpy.context.scene
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, name + ".glb"), export_lights=True, export_cameras=True)
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = os.path.join(out, name + "-blender.png")
    bpy.ops.render.render(write_still=True)


# 1. Blender's start-up scene as it comes: the grey cube, the 1000 W point light, the camera.
bpy.ops.wm.read_factory_settings(use_empty=False)
setup(bpy.context.scene)
export_and_render("default_cube")

# 2. A sun of strength 3 over a floor with a red plastic cube, a metal sphere and a glass
#    sphere (transmission 1): the material mapping.
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
setup(scene)
bpy.ops.mesh.primitive_plane_add(size=12)
bpy.context.object.data.materials.append(material("floor", (0.6, 0.6, 0.6), roughness=0.8))
bpy.ops.mesh.primitive_cube_add(size=1.2, location=(-1.6, 0, 0.6))
bpy.context.object.data.materials.append(material("red plastic", (0.7, 0.05, 0.04), roughness=0.35))
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(0.2, 0.4, 0.7), segments=64, ring_count=32)
bpy.ops.object.shade_smooth()
bpy.context.object.data.materials.append(material("gold", (1.0, 0.77, 0.34), metallic=1.0, roughness=0.25))
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(1.7, -0.6, 0.6), segments=64, ring_count=32)
bpy.ops.object.shade_smooth()
bpy.context.object.data.materials.append(material("glass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0))
sun = bpy.data.lights.new("sun", "SUN")
sun.energy = 3.0
sun.angle = math.radians(0.5)
sun_object = bpy.data.objects.new("sun", sun)
sun_object.rotation_euler = (math.radians(40), math.radians(10), math.radians(30))
scene.collection.objects.link(sun_object)
camera = bpy.data.cameras.new("camera")
camera.lens = 40
camera_object = bpy.data.objects.new("camera", camera)
camera_object.location = (0.5, -7.5, 3.6)
camera_object.rotation_euler = (math.radians(66), 0, math.radians(3))
scene.collection.objects.link(camera_object)
scene.camera = camera_object
export_and_render("sun_materials")
