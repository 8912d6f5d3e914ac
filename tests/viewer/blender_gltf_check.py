"""Run by Blender (tests/viewer/dcc_check.sh): imports the .glb of `jelly export --gltf` with
Blender's own glTF importer and its defaults, and checks that every body is one object whose
shape keys play the recording: at the scene time of a frame, its evaluated mesh has that frame's
OBJ (`jelly export --obj-sequence`) vertices, in Blender's z-up world (glTF's y-up turned by the
importer), and its material's base colour is the body's.

    blender -b --factory-startup --python-exit-code 1 --python blender_gltf_check.py -- \
        FILE.glb FRAME FRAME.obj FPS
"""
import sys

import bpy
import numpy
from mathutils import Vector
from mathutils.kdtree import KDTree

# Debian 12's Blender 3.4.1 runs on Debian's NumPy 1.24, which removed the alias numpy.bool that
# its glTF importer still uses for any mesh with normals (set_poly_smoothing: "module 'numpy' has
# no attribute 'bool'"). Blender's own builds bundle an older NumPy; here the alias is put back,
# as docs/output.md tells users of Debian's Blender to do.
if "bool" in getattr(numpy, "__former_attrs__", {}):
    numpy.bool = bool

glb, frame, expected, fps = sys.argv[sys.argv.index("--") + 1:]
frame, fps = int(frame), int(fps)
bpy.ops.wm.read_factory_settings(use_empty=True)
# The importer turns glTF seconds into scene frames at the scene's rate: at the recording's rate,
# scene frame k is recorded frame k.
bpy.context.scene.render.fps = fps
bpy.ops.import_scene.gltf(filepath=glb)

# The bodies of the OBJ frame: "o name" then its vertices (jelly's y-up coordinates).
bodies, name = {}, None
for line in open(expected):
    if line.startswith("o "):
        name = line.split()[1]
        bodies[name] = []
    elif line.startswith("v "):
        x, y, z = map(float, line.split()[1:4])
        bodies[name].append(Vector((x, -z, y)))  # y-up to Blender's z-up, as the importer does

bpy.context.scene.frame_set(frame)
depsgraph = bpy.context.evaluated_depsgraph_get()
for name, points in bodies.items():
    obj = bpy.data.objects.get(name)
    assert obj is not None, f"no object {name} (objects: {[o.name for o in bpy.data.objects]})"
    keys = obj.data.shape_keys
    assert keys is not None and len(keys.key_blocks) > frame, f"{name}: no shape key per frame"
    assert keys.animation_data is not None and keys.animation_data.action is not None, \
        f"{name}: its shape keys are not animated"
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    world = [obj.matrix_world @ v.co for v in mesh.vertices]
    # The importer may split or reorder vertices: every OBJ vertex must have an imported one at
    # its place, and the other way round.
    tree = KDTree(len(world))
    for i, p in enumerate(world):
        tree.insert(p, i)
    tree.balance()
    error = max(tree.find(p)[2] for p in points)
    back = KDTree(len(points))
    for i, p in enumerate(points):
        back.insert(p, i)
    back.balance()
    error = max(error, max(back.find(p)[2] for p in world))
    material = obj.material_slots[0].material
    colour = material.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value
    print(f"blender: {name}: {len(keys.key_blocks) - 1} shape keys, frame {frame}: "
          f"{len(points)} vertices, largest distance {error:.3g} m; base colour (linear) "
          f"{tuple(round(c, 4) for c in colour[:3])}")
    assert error < 1e-5, error
    evaluated.to_mesh_clear()
