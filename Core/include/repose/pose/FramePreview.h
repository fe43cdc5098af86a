// What a front end shows of a frame made slab by slab into its folder (FrameOutcome::streamed,
// issue 56): its posed maps do not fit in memory, so they are read back from the folder's NIfTI
// files as mode proxies (io/LabelProxy.h: each voxel the most frequent label of its block), by
// the smallest whole factor that fits. The full-resolution frame is the folder's files.
#pragma once

#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <string>

namespace repose {

struct FramePreview {
  Volume organs, parts;  // posed G and S, `factor` times coarser on each axis
  int factor = 1;
};

// The preview of the frame in `folder` (its posed_G.nii.gz and posed_S.nii.gz), G and S together
// within half of `bytes`, each read through a slice cache of a quarter of that; coarser by 2 at
// least (the frame did not fit: its preview is not a copy of it). Throws repose::Error
// naming the folder when it holds no NIfTI posed maps (a frame written as .seg.nrrd only).
FramePreview previewStreamedFrame(const std::string& folder, double bytes,
                                  const ProgressFn& progress = {});

}  // namespace repose
