// The preview of a frame made slab by slab (FramePreview.h): G and S read back by one factor.
#include "repose/pose/FramePreview.h"

#include "repose/io/LabelProxy.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/SliceCache.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <filesystem>

namespace repose {

FramePreview previewStreamedFrame(const std::string& folder, double bytes,
                                  const ProgressFn& progress) {
  const std::filesystem::path dir(folder);
  const std::string g = (dir / "posed_G.nii.gz").string(), s = (dir / "posed_S.nii.gz").string();
  if (!std::filesystem::exists(g) || !std::filesystem::exists(s))
    throw Error(folder + ": no posed_G.nii.gz and posed_S.nii.gz to preview the frame from");
  const NiftiLayout gl = readNiftiLayout(g), sl = readNiftiLayout(s);
  FramePreview out;
  out.factor = std::max(2, proxyFactor(gl.geometry.numVoxels(),
                                       scalarSize(gl.type) + scalarSize(sl.type), 0.5 * bytes));
  auto half = [&](double from) -> ProgressFn {
    if (!progress) return {};
    return
        [&, from](double f, const std::string& stage) { return progress(from + 0.5 * f, stage); };
  };
  {
    SliceCache cache(g, std::size_t(0.25 * bytes));
    out.organs = labelModeProxy(cache, out.factor, half(0));
  }
  SliceCache cache(s, std::size_t(0.25 * bytes));
  out.parts = labelModeProxy(cache, out.factor, half(0.5));
  return out;
}

}  // namespace repose
