# Renders a glTF file with Blender's Cycles, headless, as `pt render` lights a glTF file without
# lights (a uniform white sky of radiance 1), for comparing the two (docs/gltf.md, "Against
# Cycles"). A one-off comparison tool: Blender is not part of the build or the tests.
# (Blender 3.4: its glTF add-on io_scene_gltf2 imports the file.)
# Usage: blender -b --python tools/cycles-render-gltf.py -- in.gltf out.exr WIDTH HEIGHT SPP DEPTH
import json
import sys

import addon_utils
import bpy
import numpy

# Blender 3.4's glTF importer uses numpy.bool, which Debian's numpy (1.24) no longer has.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

src, out, width, height, spp, depth = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
addon_utils.enable("io_scene_gltf2", default_set=True)
bpy.ops.import_scene.gltf(filepath=src)
scene = bpy.context.scene
# glTF's Lambertian surface (KHR_materials_specular's factor 0, which Blender 3.4's importer does
# not read, neither metallic nor transmissive) would be Cycles' Principled BSDF with a specular
# layer and Disney's diffuse, brighter at grazing angles where rough: such materials get a
# Diffuse BSDF (Lambertian at roughness 0) of the base colour instead, found by their names.
lambertian = set()
for m in json.load(open(src)).get("materials", []):
    factor = m.get("extensions", {}).get("KHR_materials_specular", {}).get("specularFactor", 1.0)
    pbr = m.get("pbrMetallicRoughness", {})
    if factor == 0.0 and pbr.get("metallicFactor", 1.0) == 0.0 and "name" in m and \
            "KHR_materials_transmission" not in m.get("extensions", {}):
        lambertian.add(m["name"])
for material in bpy.data.materials:
    if material.name not in lambertian or not material.use_nodes:
        continue
    tree = material.node_tree
    for node in list(tree.nodes):
        if node.type != "BSDF_PRINCIPLED":
            continue
        diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Color"].default_value = node.inputs["Base Color"].default_value
        diffuse.inputs["Roughness"].default_value = 0.0
        for link in list(node.outputs["BSDF"].links):
            tree.links.new(diffuse.outputs["BSDF"], link.to_socket)
        tree.nodes.remove(node)
scene.camera = next(o for o in scene.objects if o.type == "CAMERA")
scene.render.engine = "CYCLES"
c = scene.cycles
c.device = "CPU"
c.samples = int(spp)
c.use_denoising = False
c.use_adaptive_sampling = False
for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
             "volume_bounces", "transparent_max_bounces"):
    setattr(c, name, int(depth))
c.sample_clamp_direct = 0.0
c.sample_clamp_indirect = 0.0
c.blur_glossy = 0.0
c.caustics_reflective = True
c.caustics_refractive = True
c.filter_width = 0.01  # a pixel's own samples only (pt's box filter of half a pixel)
world = bpy.data.worlds.new("sky")
world.use_nodes = True
background = world.node_tree.nodes["Background"]
background.inputs[0].default_value = (1.0, 1.0, 1.0, 1.0)
background.inputs[1].default_value = 1.0
scene.world = world
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0
scene.render.resolution_x = int(width)
scene.render.resolution_y = int(height)
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
