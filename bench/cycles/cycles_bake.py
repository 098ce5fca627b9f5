# Bakes E/pi of a glTF scene with Blender's Cycles into the atlas pages of an Exitance bundle, texel
# for texel, so the two can be compared (bench/results/cycles-equal-time.md). Run by Blender:
#   blender -b --python-exit-code 1 -P bench/cycles/cycles_bake.py -- SCENE.gltf BUNDLE OUT_PREFIX SAMPLES [THREADS [SKY [SEED]]]
# Writes OUT_PREFIX-<page>.pfm (R, G, B = E/pi, linear float) and prints "cycles_bake_seconds S" (the
# bake call alone: scene sync, BVH and path tracing).
#
# The pages are written from the image's pixels with numpy, not with Image.save(): Blender 3.4's save
# of a float image applies the scene's display transform (Filmic and sRGB) even to OpenEXR, which made
# a first comparison read Cycles about 2x brighter and whiter than it is.
#
# What is set up so Cycles computes the same quantity as `bake`:
# - every material becomes a Diffuse BSDF (roughness 0: Lambert) of the glTF base colour factor,
#   plus its emission on front faces only (glTF emission is one-sided in Exitance; Cycles mesh lights
#   emit from both sides unless masked with Geometry > Backfacing);
# - DIFFUSE bake with the direct and indirect passes and no colour pass: irradiance over pi;
# - unbounded bounces (1024), no clamping, black world unless --sky is given as R,G,B;
# - each object's TEXCOORD_1 (Blender's second UV map) is mapped through its instance's scale_offset
#   from BUNDLE/manifest.json into the page, so baked pixels are the bundle's texels.
import json
import os
import sys
import time

import numpy

numpy.bool = bool  # Blender 3.4's glTF importer still uses the removed alias
import bpy  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
scene_path, bundle, out_prefix, samples = argv[0], argv[1], argv[2], int(argv[3])
threads = int(argv[4]) if len(argv) > 4 else 0
sky = [float(x) for x in argv[5].split(",")] if len(argv) > 5 else [0.0, 0.0, 0.0]
seed = int(argv[6]) if len(argv) > 6 else 0

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_path)
manifest = json.load(open(os.path.join(bundle, "manifest.json")))
pages = manifest["pages"]

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.seed = seed
scene.cycles.use_adaptive_sampling = False
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 1024
scene.cycles.diffuse_bounces = 1024
scene.cycles.glossy_bounces = 0
scene.cycles.transmission_bounces = 0
scene.cycles.volume_bounces = 0
scene.cycles.transparent_max_bounces = 0
scene.cycles.sample_clamp_direct = 0
scene.cycles.sample_clamp_indirect = 0
scene.cycles.caustics_reflective = False
scene.cycles.caustics_refractive = False
if threads:
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
world = bpy.data.worlds.new("black") if scene.world is None else scene.world
scene.world = world
world.use_nodes = True
background = world.node_tree.nodes.get("Background") or world.node_tree.nodes.new("ShaderNodeBackground")
background.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
background.inputs["Strength"].default_value = 1.0
world_output = world.node_tree.nodes.get("World Output") or world.node_tree.nodes.new("ShaderNodeOutputWorld")
world.node_tree.links.new(background.outputs["Background"], world_output.inputs["Surface"])

images = [bpy.data.images.new("page%d" % i, p["width"], p["height"], float_buffer=True, alpha=False) for i, p in enumerate(pages)]


def lambert_material(source, page_image):
    """A copy of `source` as Lambert + front-face emission, with the page image as the bake target."""
    base = (0.8, 0.8, 0.8, 1.0)
    emission = (0.0, 0.0, 0.0, 1.0)
    strength = 1.0
    if source is not None and source.use_nodes:
        for n in source.node_tree.nodes:
            if n.type == "BSDF_PRINCIPLED":
                base = tuple(n.inputs["Base Color"].default_value)
                emission = tuple(n.inputs["Emission"].default_value)
                strength = n.inputs["Emission Strength"].default_value
    m = bpy.data.materials.new((source.name if source else "default") + "-lambert")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = base
    diffuse.inputs["Roughness"].default_value = 0.0
    emit = nt.nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = emission
    geometry = nt.nodes.new("ShaderNodeNewGeometry")
    front = nt.nodes.new("ShaderNodeMath")
    front.operation = "SUBTRACT"
    front.inputs[0].default_value = 1.0
    nt.links.new(geometry.outputs["Backfacing"], front.inputs[1])
    scale = nt.nodes.new("ShaderNodeMath")
    scale.operation = "MULTIPLY"
    scale.inputs[1].default_value = strength
    nt.links.new(front.outputs[0], scale.inputs[0])
    nt.links.new(scale.outputs[0], emit.inputs["Strength"])
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
    nt.links.new(emit.outputs["Emission"], add.inputs[1])
    nt.links.new(add.outputs["Shader"], out.inputs["Surface"])
    target = nt.nodes.new("ShaderNodeTexImage")
    target.image = page_image
    nt.nodes.active = target
    return m


by_name = {o.name: o for o in bpy.data.objects if o.type == "MESH"}
baked = []
for inst in manifest["instances"]:
    obj = by_name.get(inst.get("name", ""))
    if obj is None:
        raise SystemExit("cycles_bake: no Blender object named %r (instance of node %d)" % (inst.get("name"), inst["node"]))
    obj.data = obj.data.copy()  # instances sharing a mesh get their own UVs
    mesh = obj.data
    if len(mesh.uv_layers) < 2:
        raise SystemExit("cycles_bake: %s has no TEXCOORD_1" % obj.name)
    sx, sy, ox, oy = inst["scale_offset"]
    layer = mesh.uv_layers[1]
    for loop_uv in layer.data:
        u, v = loop_uv.uv
        v_gltf = 1.0 - v
        loop_uv.uv = (u * sx + ox, 1.0 - (v_gltf * sy + oy))
    mesh.uv_layers.active = layer
    image = images[inst["page"]]
    sources = [s.material for s in obj.material_slots] or [None]
    if not obj.material_slots:
        obj.data.materials.append(None)
    for k, s in enumerate(obj.material_slots):
        s.material = lambert_material(sources[k] if k < len(sources) else None, image)
    baked.append(obj)

bpy.ops.object.select_all(action="DESELECT")
for o in baked:
    o.select_set(True)
bpy.context.view_layer.objects.active = baked[0]
start = time.perf_counter()
bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT", "INDIRECT"}, margin=0, use_clear=True,
                    target="IMAGE_TEXTURES")
seconds = time.perf_counter() - start
print("cycles_bake_seconds %.3f" % seconds)
for i, image in enumerate(images):
    width, height = image.size
    rgba = numpy.array(image.pixels[:], dtype="<f4").reshape(height, width, 4)
    with open("%s-%d.pfm" % (out_prefix, i), "wb") as pfm:  # PFM rows run bottom to top, as Blender's
        pfm.write(b"PF\n%d %d\n-1.0\n" % (width, height))
        pfm.write(numpy.ascontiguousarray(rgba[:, :, :3]).tobytes())
