"""Renders a .vdb that `cumulus export` wrote with Blender's Cycles, set
up as the README tells a Blender user to (runs in Blender's Python: the
`bpy` wheel, `pip install bpy==4.5.15` into a Python 3.11 venv;
blender_check.py calls it):
- the volume object scaled by -1 along its own z and turned 90 degrees
  about x: our x east, y up, z north (a left-handed labelling) become
  Blender's x east, y north, z up, and its pictures are ours, not their
  mirror image;
- its material the phase function exactly ("lobes", the default): one
  Volume Scatter per Henyey-Greenstein lobe of the sidecar, whose
  density is the `density` attribute times the lobe's weight times the
  albedo, and a Volume Absorption of the rest; or ("principled") one
  Principled Volume at density 1, colour the albedo, anisotropy the
  phase's mean cosine, to measure what one lobe costs;
- the sidecar's sun (irradiance, direction) and camera turned the same
  way; the exported sky (Mitsuba's envmap layout) resampled into
  Blender's equirectangular layout as the world;
- every bounce kept (1024 volume bounces, no clamping, no denoising).

Writes OUT.npy, linear RGB, in our image's orientation (compare.py
mirrors Mitsuba's, whose world is right-handed); or, when OUT ends in
.blend, saves the scene set up (nothing rendered) for Blender to open,
with the sky image packed into it:

    python blender_render.py VOLUME.vdb SKY.exr OUT WIDTH HEIGHT SPP [lobes|principled]
    python blender_render.py clouds.vdb sky.exr clouds.blend 1280 720 256
"""
import json
import math
import sys

import bpy
import numpy as np
from mathutils import Matrix, Vector

vdb, sky_path, out, width, height, spp = sys.argv[1:7]
width, height, spp = int(width), int(height), int(spp)
side = json.load(open(vdb[:-4] + ".json"))


def to_blender(v):
    """Our world (x east, y up, z north: left-handed) as Blender's (x
    east, y north, z up): y and z swapped, the volume object's 90 degree
    turn about x after its scale of -1 along its own z."""
    return Vector((v[0], v[2], v[1]))


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = spp
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 1024
scene.cycles.volume_bounces = 1024
scene.cycles.transparent_max_bounces = 1024
scene.cycles.diffuse_bounces = 0
scene.cycles.glossy_bounces = 0
scene.cycles.sample_clamp_indirect = 0
scene.cycles.sample_clamp_direct = 0
scene.render.resolution_x = width
scene.render.resolution_y = height
scene.render.resolution_percentage = 100
scene.render.filter_size = 0.01
scene.view_settings.view_transform = "Standard"

# The volume.
bpy.ops.object.volume_import(filepath=vdb)
vol = bpy.context.object
vol.rotation_euler = (math.radians(90.0), 0.0, 0.0)
vol.scale = (1.0, 1.0, -1.0)
mat = bpy.data.materials.new("clouds")
mat.use_nodes = True
nodes, links = mat.node_tree.nodes, mat.node_tree.links
nodes.clear()
PHASE = sys.argv[7] if len(sys.argv) > 7 else "lobes"
o = nodes.new("ShaderNodeOutputMaterial")
a = side["albedo"]
if PHASE == "principled":
    pv = nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Density"].default_value = 1.0
    pv.inputs["Color"].default_value = (a, a, a, 1.0)
    pv.inputs["Anisotropy"].default_value = sum(l["weight"] * l["g"] for l in side["phase"])
    links.new(pv.outputs["Volume"], o.inputs["Volume"])
else:
    # The phase function exactly: one Volume Scatter per lobe, its
    # density the lobe's share of the scattering, and the absorption.
    attr = nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "density"
    parts = [(l["weight"] * a, l["g"], "scatter") for l in side["phase"]] + [(1.0 - a, 0.0, "absorb")]
    total = None
    for w, g, kind in parts:
        mul = nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY"
        mul.inputs[1].default_value = w
        links.new(attr.outputs["Fac"], mul.inputs[0])
        if kind == "scatter":
            sh = nodes.new("ShaderNodeVolumeScatter")
            sh.inputs["Color"].default_value = (1, 1, 1, 1)
            sh.inputs["Anisotropy"].default_value = g
        else:
            sh = nodes.new("ShaderNodeVolumeAbsorption")
            sh.inputs["Color"].default_value = (0, 0, 0, 1)
        links.new(mul.outputs[0], sh.inputs["Density"])
        if total is None:
            total = sh.outputs[0]
        else:
            add = nodes.new("ShaderNodeAddShader")
            links.new(total, add.inputs[0])
            links.new(sh.outputs[0], add.inputs[1])
            total = add.outputs[0]
    links.new(total, o.inputs["Volume"])
vol.data.materials.append(mat)

# The sun.
sun_rgb = np.array(side["sun_irradiance_rgb"])
light = bpy.data.lights.new("sun", "SUN")
light.energy = float(sun_rgb.max())
light.color = tuple(sun_rgb / sun_rgb.max())
light.angle = math.radians(0.53)
sun = bpy.data.objects.new("sun", light)
scene.collection.objects.link(sun)
d = to_blender(side["sun_direction"]).normalized()
sun.rotation_euler = (-d).to_track_quat("-Z", "Y").to_euler()

# The camera.
cam_data = bpy.data.cameras.new("camera")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(side["camera_fov_y_deg"])
cam_data.clip_end = 1e6
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
eye = to_blender(side["camera_origin_m"])
fwd = (to_blender(side["camera_target_m"]) - eye).normalized()
up = to_blender(side["camera_up"])
right = fwd.cross(up).normalized()
up = right.cross(fwd)
m = Matrix((right, up, -fwd)).transposed().to_4x4()
m.translation = eye
cam.matrix_world = m
scene.camera = cam

# The sky: our envmap (Mitsuba's layout, y up) resampled into Blender's
# equirectangular layout (z up, image rows from the bottom).
src = bpy.data.images.load(sky_path)
sw, sh = src.size
pix = np.array(src.pixels[:], dtype=np.float32).reshape(sh, sw, 4)[::-1, :, :3]  # row 0 at the top
bw, bh = 1024, 512
u = (np.arange(bw) + 0.5) / bw
v = (np.arange(bh) + 0.5) / bh
phi = (0.5 - u) * 2 * math.pi  # atan2(y, x) in Blender's world
el = (v - 0.5) * math.pi  # asin(z), rows from the bottom
X = np.cos(el)[:, None] * np.cos(phi)[None, :]
Y = np.cos(el)[:, None] * np.sin(phi)[None, :]
Z = np.sin(el)[:, None] * np.ones_like(phi)[None, :]
# Back to our world: x = X, y = Z, z = Y.
x, y, z = X, Z, Y
um = (np.arctan2(x, -z) / (2 * math.pi)) % 1.0
vm = np.arccos(np.clip(y, -1, 1)) / math.pi
ii = np.clip((um * sw).astype(int), 0, sw - 1)
jj = np.clip((vm * sh).astype(int), 0, sh - 1)
res = pix[jj, ii]
img = bpy.data.images.new("sky", bw, bh, float_buffer=True, alpha=False)
rgba = np.concatenate([res, np.ones((bh, bw, 1), np.float32)], axis=2)
img.pixels[:] = rgba.ravel()
world = bpy.data.worlds.new("world")
scene.world = world
world.use_nodes = True
wn = world.node_tree.nodes
wn.clear()
env = wn.new("ShaderNodeTexEnvironment")
env.image = img
bg = wn.new("ShaderNodeBackground")
wo = wn.new("ShaderNodeOutputWorld")
world.node_tree.links.new(env.outputs["Color"], bg.inputs["Color"])
world.node_tree.links.new(bg.outputs["Background"], wo.inputs["Surface"])

if out.endswith(".blend"):
    img.pack()
    vol.data.filepath = bpy.path.abspath(vdb)
    bpy.ops.wm.save_as_mainfile(filepath=out)
    sys.exit(0)

scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.filepath = out + ".exr"
bpy.ops.render.render(write_still=True)
r = bpy.data.images.load(out + ".exr")
a = np.array(r.pixels[:], dtype=np.float32).reshape(height, width, 4)[::-1, :, :3]
np.save(out, a)
