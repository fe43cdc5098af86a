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
ls -l "$DOCS"
