#!/usr/bin/env bash
# `make demo`: the main job on generated phantoms. Generates the 2 mm phantom with its synthetic
# CT (and its arms-touching variant), runs the standard pose suite of bench/poses/ with
# `repose pose` (the cage and transfer mesh are built once per phantom and reused through a
# scene folder), plots each report, renders the workbench on the elbow scene (under xvfb-run),
# and prints where everything is and which quality targets were met.
set -euo pipefail
BUILD_DIR=${1:-build}
DEMO_DIR=${2:-$BUILD_DIR/demo}
REPOSE="$BUILD_DIR/bin/repose"
POSES="$(dirname "$0")/../bench/poses"

mkdir -p "$DEMO_DIR/poses"
echo "== generating the 2 mm phantom in $DEMO_DIR/phantom"
"$REPOSE" phantom --voxel 2 --image --out "$DEMO_DIR/phantom"
"$REPOSE" info "$DEMO_DIR/phantom/G.nii.gz" | head -8
echo
echo "== generating the arms-touching 2 mm phantom in $DEMO_DIR/phantom_touching"
"$REPOSE" phantom --voxel 2 --image --arms-touching --out "$DEMO_DIR/phantom_touching"

# `repose pose` exits 4 when it wrote every frame but some missed a quality target: the table at
# the end says which; the demo goes on.
pose_or_missed() {
  local status=0
  "$REPOSE" pose "$@" || status=$?
  [ "$status" -eq 0 ] || [ "$status" -eq 4 ]
}
run_pose() {  # phantom-folder pose-name
  echo
  echo "== pose $2 on $1"
  pose_or_missed --input "$DEMO_DIR/$1/G.nii.gz" --parts "$DEMO_DIR/$1/S.nii.gz" \
    --image "$DEMO_DIR/$1/CT.nii.gz" --background -1000 \
    --pose "$POSES/$2.pose.json" --scene "$DEMO_DIR/$1/scene" --out "$DEMO_DIR/poses/$2"
}
for pose in elbow90 arm_raise90 leg_step30 walk; do run_pose phantom "$pose"; done
run_pose phantom_touching hand_from_hip

# A user's own segmentation: only G of the arms-resting phantom (arms on the trunk, hands on the
# thighs, thighs touching) goes in; `repose rig` makes S, the skeleton and the tissue table, and
# the suite's named-joint poses run on that rig with automatic contact separation.
echo
echo "== your own segmentation: rig the arms-resting 2 mm phantom from G alone"
"$REPOSE" phantom --voxel 2 --arms-resting --out "$DEMO_DIR/phantom_resting"
"$REPOSE" rig --input "$DEMO_DIR/phantom_resting/G.nii.gz" --out "$DEMO_DIR/phantom_resting/rig"
/usr/bin/python3 "$(dirname "$0")/plot-rig.py" "$DEMO_DIR/phantom_resting/G.nii.gz" \
  "$DEMO_DIR/phantom_resting/rig" "$DEMO_DIR/rig_resting.png" | sed 's/^/  picture of S and the joints: /'
for pose in arm_raise90 leg_step30; do
  echo
  echo "== pose $pose on the rigged arms-resting phantom"
  pose_or_missed --input "$DEMO_DIR/phantom_resting/G.nii.gz" \
    --parts "$DEMO_DIR/phantom_resting/rig/S.nii.gz" --pose "$POSES/$pose.pose.json" \
    --out "$DEMO_DIR/poses/resting_$pose"
done

echo
echo "== plots"
find "$DEMO_DIR/poses" -name report.json | sort | xargs /usr/bin/python3 "$(dirname "$0")/plot-report.py" | sed 's/^/  /'

echo
echo "== the workbench on the elbow scene (four views: slices of the posed labels over the CT, 3D)"
if command -v xvfb-run >/dev/null; then
  # The scene folder's pose is the last one posed on this phantom: write the elbow's beside it.
  cp -r "$DEMO_DIR/phantom/scene" "$DEMO_DIR/scene_elbow90"
  rm -f "$DEMO_DIR"/scene_elbow90/*.pose.json
  cp "$POSES/elbow90.pose.json" "$DEMO_DIR/scene_elbow90/"
  /usr/bin/python3 - "$DEMO_DIR/scene_elbow90/scene.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
for node in scene["nodes"]:
    if node["class"] == "vtkMRMLReposePoseNode":
        node["FileName"] = "elbow90.pose.json"
        node["name"] = "elbow90"
json.dump(scene, open(sys.argv[1], "w"), indent=2)
PY
  xvfb-run -a -s "-screen 0 1600x1000x24" "$BUILD_DIR/bin/ReposeWorkbench" \
    --scene "$DEMO_DIR/scene_elbow90" --screenshot "$DEMO_DIR/workbench_elbow90.png"
  echo "  $DEMO_DIR/workbench_elbow90.png"
else
  echo "  skipped: xvfb-run is not installed (apt-get install xvfb)"
fi

echo
echo "== quality targets (docs/QUALITY.md)"
/usr/bin/python3 - "$DEMO_DIR/poses" <<'PY'
import json, pathlib, sys
rows = []
for p in sorted(pathlib.Path(sys.argv[1]).rglob("report.json")):
    r = json.load(open(p)); q = r["quality"]
    rows.append((str(p.parent.relative_to(sys.argv[1])), r["body"]["volume_change_percent"],
                 q["labels_within_1_percent"]["worst_change_percent"],
                 q.get("bones_rigid", {}).get("min_dice", float("nan")),
                 q["no_new_holes"]["new_enclosed_voxels"], r["pockets"]["filled_voxels"],
                 r["mesh"]["inverted_tets"], q["all_met"]))
print(f"  {'frame':28} {'body %':>8} {'worst label %':>14} {'bones Dice':>10} {'new holes':>9} {'filled':>7} {'inverted':>8}  all met")
for f, b, w, d, h, p, i, a in rows:
    print(f"  {f:28} {b:8.3f} {w:14.3f} {d:10.3f} {h:9d} {p:7d} {i:8d}  {'yes' if a else 'no'}")
PY
echo
echo "Demo outputs are in $DEMO_DIR: phantom*/ (G, S, CT, skeleton, scene/ with cage.vtk and tm.vtu),"
echo "phantom_resting/rig/ (S, skeleton, tissues, rig.json from G alone) and rig_resting.png,"
echo "poses/<pose>[/<frame>]/ (posed_G.nii.gz, posed_S.nii.gz, transform.nrrd, report.json, *.png)."
