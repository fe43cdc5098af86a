#include "repose/raster/RasterFile.h"

#include "repose/io/NiftiIO.h"

#include <algorithm>
#include <vector>

namespace repose {

void rasterizeLabelsToFile(SliceCache& input, const TransferMesh& mesh,
                           const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                           const std::string& path, std::size_t slabBytes,
                           const RasterOptions& options, RasterReport* report) {
  output.validate(path);
  const NiftiLayout& layout = input.layout();
  LabelSlabRasterizer slabs(input, mesh, deformed, output, options);
  const std::int64_t slab =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(slabBytes) / slabs.sliceBytes());
  NiftiSlabWriter writer(path, output, layout.type, layout.labels, true);
  RasterReport total;
  std::vector<char> buffer;
  for (std::int64_t k0 = 0; k0 < output.dims[2]; k0 += slab) {
    const std::int64_t k1 = std::min(output.dims[2], k0 + slab);
    buffer.resize(static_cast<std::size_t>((k1 - k0) * slabs.sliceBytes()));
    slabs.rasterize(k0, k1, buffer.data(), total, [&](double f, const std::string& stage) {
      return !options.progress ||
             options.progress((double(k0) + f * double(k1 - k0)) / double(output.dims[2]), stage);
    });
    writer.writeSlices(buffer.data(), k1 - k0);
  }
  writer.finish();
  if (report) *report = total;
}

}  // namespace repose
