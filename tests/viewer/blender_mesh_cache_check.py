"""Run by Blender (tests/viewer/dcc_check.sh): imports the rest surface OBJ of `jelly export --pc2`,
adds a Mesh Cache modifier reading the PC2 file with its default settings, and checks that the
evaluated mesh at a frame equals that frame's OBJ of `jelly export --obj-sequence`.

    blender -b --factory-startup --python-exit-code 1 --python blender_mesh_cache_check.py -- \
        REST.obj CACHE.pc2 FRAME FRAME.obj
"""
import sys

import bpy

rest, pc2, frame, expected = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=rest)  # Blender's defaults: forward -Z, up Y
assert len(bpy.context.selected_objects) == 1, "the rest OBJ is one object (its groups: the bodies)"
obj = bpy.context.selected_objects[0]
cache = obj.modifiers.new("jelly", "MESH_CACHE")
cache.cache_format = "PC2"
cache.filepath = pc2
bpy.context.scene.frame_set(int(frame))  # frame_start 0: scene frame k shows sample k
mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
# The importer keeps jelly's y-up coordinates in the mesh and turns the object to Blender's z-up.
points = [tuple(map(float, line.split()[1:4])) for line in open(expected) if line.startswith("v ")]
assert len(points) == len(mesh.vertices), (len(points), len(mesh.vertices))
error = max(max(abs(a - b) for a, b in zip(v.co, p)) for v, p in zip(mesh.vertices, points))
world = obj.matrix_world @ mesh.vertices[0].co
print(f"blender: {len(points)} vertices, largest difference {error:.3g} m; "
      f"vertex 0 in Blender's z-up world {tuple(round(c, 6) for c in world)}")
assert error < 1e-5, error
