#!/usr/bin/env bash
# The pictures of docs/USER_GUIDE.md: the GUI test run on a 4 mm phantom (finer than the 8 mm of
# `make test`) saves the panel and views at each step; the workbench renders the demo's elbow
# scene. Needs a build and, for the last picture, `make demo` (build/demo/scene_elbow90).
set -euo pipefail
BUILD_DIR=${1:-build}
DOCS="$(dirname "$0")/../docs/images"
mkdir -p "$DOCS"
REPOSE_TEST_PHANTOM_MM=4 xvfb-run -a -s "-screen 0 1600x1200x24" \
  "$BUILD_DIR/bin/qSlicerReposeViewsTest" posingWithTheCageInTheThreeDView
REPOSE_TEST_PHANTOM_MM=4 xvfb-run -a -s "-screen 0 1600x1200x24" \
  "$BUILD_DIR/bin/qSlicerReposeViewsTest" posingThroughThePanelUpdatesTheViews
REPOSE_TEST_PHANTOM_MM=4 xvfb-run -a -s "-screen 0 1600x1200x24" \
  "$BUILD_DIR/bin/qSlicerReposeViewsTest" ownSegmentationShowsNamedColouredLabelsAndTheProbe
REPOSE_TEST_PHANTOM_MM=4 xvfb-run -a -s "-screen 0 1600x1200x24" \
  "$BUILD_DIR/bin/qSlicerReposeViewsTest" bodyPartsOutlinedAndJointsDrawnWhereTheFrameMovesThem
for f in guide_1_rig_built guide_2_part_selected guide_3_hand_moved guide_4_exported \
  guide_own_1_open guide_own_2_rigged guide_own_3_probe guide_own_4_joint guide_own_5_exported \
  parts_and_joints; do
  cp "$BUILD_DIR/Testing/Artifacts/$f.png" "$DOCS/$f.png"
done
if [ -f "$BUILD_DIR/demo/workbench_elbow90.png" ]; then
  cp "$BUILD_DIR/demo/workbench_elbow90.png" "$DOCS/workbench_elbow90.png"
fi
# The workbench as a user first sees it (issue 55): 1280 x 800, a phantom of a reference
# phantom's size and slices (1.8 x 1.8 x 4.8 mm), its elbow scene opened with the suite's pose
# (named joints): the panel's fields whole, the 3D view from the front.
REAL="$(mktemp -d)"
trap 'rm -rf "$REAL"' EXIT
"$BUILD_DIR/bin/repose" phantom --out "$REAL/body" --arms-resting --spacing 1.8,1.8,4.8 --image \
  >/dev/null
POSE="$(dirname "$0")/../bench/poses/elbow90.pose.json"
"$BUILD_DIR/bin/repose" pose --input "$REAL/body/G.nii.gz" --parts "$REAL/body/S.nii.gz" \
  --image "$REAL/body/CT.nii.gz" --pose "$POSE" --scene "$REAL/scene" --out "$REAL/out" >/dev/null
cp "$POSE" "$REAL/scene/elbow90.pose.json"
xvfb-run -a -s "-screen 0 1280x800x24" "$BUILD_DIR/bin/ReposeWorkbench" \
  --scene "$REAL/scene" --screenshot "$DOCS/workbench_1280x800.png"
ls -l "$DOCS"
