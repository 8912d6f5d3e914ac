#!/usr/bin/env bash
# The exports in the tools they are for: Blender's Mesh Cache modifier reads the PC2 file onto the
# rest OBJ, Blender's glTF importer reads the .glb, and ParaView reads the OBJ sequence through
# scripts/paraview_obj_sequence.py; each must give frame 30 of the recording, for the seed slope
# and for a scene of three bodies.
# Skipped (exit 77) when the tool is not installed.
#   dcc_check.sh blender|paraview JELLY SOURCE_DIR
set -euo pipefail
tool=$1 jelly=$2 source=$3
case $tool in
  blender) command -v blender >/dev/null || { echo "skipped: blender is not installed"; exit 77; } ;;
  paraview) command -v pvpython >/dev/null || { echo "skipped: pvpython (paraview) is not installed"; exit 77; } ;;
esac
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for scene in "$source/scenes/seed_slope.json" "$source/tests/viewer/three_bodies.json"; do
  echo "== $(basename "$scene")"
  rm -rf "$dir"/*
  "$jelly" run "$scene" --duration 0.75 --quiet -o "$dir/r.h5" >/dev/null
  "$jelly" export "$dir/r.h5" --obj-sequence "$dir/objs" --pc2 "$dir/r.pc2" --gltf "$dir/r.glb" \
    >/dev/null
  frame="$dir/objs/frame_0030.obj"
  case $tool in
    blender)
      blender -b --factory-startup --python-exit-code 1 \
        --python "$source/tests/viewer/blender_mesh_cache_check.py" -- \
        "$dir/r.obj" "$dir/r.pc2" 30 "$frame" 2>&1 | grep "^blender:\|Error"
      # Both scenes record a frame every 1/60 s.
      blender -b --factory-startup --python-exit-code 1 \
        --python "$source/tests/viewer/blender_gltf_check.py" -- \
        "$dir/r.glb" 30 "$frame" 60 2>&1 | grep "^blender:\|Error"
      ;;
    paraview)
      out=$(pvpython "$source/scripts/paraview_obj_sequence.py" "$dir/objs" --check 30 2>&1)
      echo "$out"
      first=$(grep -m1 '^v ' "$frame" | cut -d' ' -f2-)
      grep -q "^time steps: 46$" <<<"$out"
      grep -q "^frame 30: $(grep -c '^v ' "$frame") points, $(grep -c '^f ' "$frame") cells, first point $first$" <<<"$out"
      ;;
  esac
done
