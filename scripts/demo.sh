#!/usr/bin/env bash
# `make demo`: the main job on a generated phantom. For now (issue 2) it generates the 2 mm
# phantom, describes it, converts it to a Slicer segmentation, builds its cage and its transfer
# mesh; posing comes with later issues.
set -euo pipefail
BUILD_DIR=${1:-build}
DEMO_DIR=${2:-$BUILD_DIR/demo}
REPOSE="$BUILD_DIR/bin/repose"

mkdir -p "$DEMO_DIR"
echo "== generating the 2 mm phantom in $DEMO_DIR/phantom"
"$REPOSE" phantom --voxel 2 --out "$DEMO_DIR/phantom"
echo
echo "== organ map G"
"$REPOSE" info "$DEMO_DIR/phantom/G.nii.gz"
echo
echo "== body-part map S"
"$REPOSE" info "$DEMO_DIR/phantom/S.nii.gz"
echo
echo "== G as a 3D Slicer segmentation"
"$REPOSE" convert "$DEMO_DIR/phantom/G.nii.gz" "$DEMO_DIR/phantom/G.seg.nrrd"
echo
echo "== the control cage (300 vertices, 10 mm dilation)"
"$REPOSE" cage --parts "$DEMO_DIR/phantom/S.nii.gz" --out "$DEMO_DIR/phantom/cage.vtk" --vertices 300
echo
echo "== the transfer mesh, embedded in the cage"
"$REPOSE" mesh --parts "$DEMO_DIR/phantom/S.nii.gz" --cage "$DEMO_DIR/phantom/cage.vtk" --out "$DEMO_DIR/phantom/tm.vtu"
echo
echo "Demo outputs are in $DEMO_DIR/phantom: G and S (.nii.gz), skeleton.json, G.seg.nrrd, cage.vtk, tm.vtu."
