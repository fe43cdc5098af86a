// The posed image and the displacement field, slab by slab (ImageSlabs, DisplacementSlabs) and
// whole (rasterizeImage, rasterizeDisplacement: one slab of every slice). A frame too large for
// memory is made of slabs; the whole-grid functions are the same code, so both give the same
// values voxel for voxel.
#include "RasterScan.h"
#include "repose/raster/Rasterizer.h"

#include <Eigen/LU>

#include <cmath>
#include <limits>
#include <string>

namespace repose {
namespace {

using raster::ScanInput;

void addCounts(const RasterReport& part, RasterReport& report) {
  report.voxelWrites += part.voxelWrites;
  report.shellVoxels += part.shellVoxels;
  report.invertedTets = part.invertedTets;  // of the whole mesh: the same for every slab
  report.flatTets = part.flatTets;
}

}  // namespace

struct ImageSlabs::Impl {
  const Volume& image;
  const TransferMesh& mesh;
  VolumeGeometry output;
  double background;
  RasterOptions options;
  ScanInput in;
  raster::Shell shell;
  Impl(const Volume& i, const TransferMesh& m, const Eigen::MatrixX3d& deformed,
       const VolumeGeometry& grid, double b, const RasterOptions& o)
      : image(i),
        mesh(m),
        output(grid),
        background(b),
        options(o),
        in(raster::makeScanInput(m, deformed, i.geometry(), grid)),
        shell(raster::makeShell(m, i.geometry(), grid, o)) {
    options.progress = nullptr;  // per slab (rasterize)
  }
};

ImageSlabs::ImageSlabs(const Volume& image, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                       double background, const RasterOptions& options) {
  raster::checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  if (image.layers() != 1) throw Error("rasterizer: an intensity image must have one layer");
  impl_ = std::make_unique<Impl>(image, mesh, deformed, output, background, options);
}

ImageSlabs::~ImageSlabs() = default;

std::int64_t ImageSlabs::sliceBytes() const {
  return impl_->output.dims[0] * impl_->output.dims[1] *
         static_cast<std::int64_t>(scalarSize(impl_->image.scalarType()));
}

void ImageSlabs::rasterize(std::int64_t k0, std::int64_t k1, void* slab, RasterReport& report,
                           const ProgressFn& progress) const {
  const Impl& r = *impl_;
  raster::checkSlab(k0, k1, r.output);
  RasterOptions options = r.options;
  options.progress = progress;
  const auto d = r.image.dims();
  const std::int64_t nx = r.output.dims[0], plane = nx * r.output.dims[1];
  dispatchScalar(r.image.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const T fill = raster::fromDouble<T>(r.background);
    T* dst = static_cast<T*>(slab);
    std::fill(dst, dst + (k1 - k0) * plane, fill);
    const T* src = r.image.data<T>();
    RasterReport part;
    raster::runScan(
        r.in, r.shell, options, "rasterize image", &part, raster::frameSign(r.output),
        [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
            const Eigen::Vector3d& step, std::int32_t) {
          const std::int64_t row = (k - k0) * plane + j * nx;
          for (std::int64_t i = i0; i <= i1; ++i, p += step) {
            // Trilinear over the 8 voxel centres around p, clamped at the grid's edge;
            // background beyond half a voxel outside it.
            if (!(p.x() >= -0.5 && p.y() >= -0.5 && p.z() >= -0.5 && p.x() <= d[0] - 0.5 &&
                  p.y() <= d[1] - 0.5 && p.z() <= d[2] - 0.5)) {
              dst[row + i] = fill;
              continue;
            }
            const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
            const double tx = p.x() - fx, ty = p.y() - fy, tz = p.z() - fz;
            auto clampTo = [](double f, std::int64_t n) {
              return std::clamp<std::int64_t>(std::int64_t(f), 0, n - 1);
            };
            const std::int64_t x = clampTo(fx, d[0]), y = clampTo(fy, d[1]), z = clampTo(fz, d[2]);
            const std::int64_t x1 = clampTo(fx + 1, d[0]), y1 = clampTo(fy + 1, d[1]),
                               z1 = clampTo(fz + 1, d[2]);
            auto v = [&](std::int64_t a, std::int64_t b, std::int64_t c) {
              return double(src[a + d[0] * (b + d[1] * c)]);
            };
            const double c00 = v(x, y, z) * (1 - tx) + v(x1, y, z) * tx;
            const double c10 = v(x, y1, z) * (1 - tx) + v(x1, y1, z) * tx;
            const double c01 = v(x, y, z1) * (1 - tx) + v(x1, y, z1) * tx;
            const double c11 = v(x, y1, z1) * (1 - tx) + v(x1, y1, z1) * tx;
            const double c0 = c00 * (1 - ty) + c10 * ty, c1 = c01 * (1 - ty) + c11 * ty;
            dst[row + i] = raster::fromDouble<T>(c0 * (1 - tz) + c1 * tz);
          }
        },
        k0, k1);
    addCounts(part, report);
  });
}

Volume rasterizeImage(const Volume& image, const TransferMesh& mesh,
                      const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                      double background, const RasterOptions& options, RasterReport* report) {
  const ImageSlabs slabs(image, mesh, deformed, output, background, options);
  Volume out(output, image.scalarType());
  RasterReport counts;
  slabs.rasterize(0, output.dims[2], out.layerData(0), counts, options.progress);
  if (report) *report = counts;
  return out;
}

struct DisplacementSlabs::Impl {
  VolumeGeometry input, output;
  RasterOptions options;
  ScanInput in;
  raster::Shell shell;
  Impl(const TransferMesh& m, const Eigen::MatrixX3d& deformed, const VolumeGeometry& i,
       const VolumeGeometry& o, const RasterOptions& opt)
      : input(i),
        output(o),
        options(opt),
        in(raster::makeScanInput(m, deformed, i, o)),
        shell(raster::makeShell(m, i, o, opt)) {
    options.progress = nullptr;  // per slab (rasterize)
  }
};

DisplacementSlabs::DisplacementSlabs(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                     const VolumeGeometry& input, const VolumeGeometry& output,
                                     const RasterOptions& options) {
  raster::checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  input.validate("rasterizer input grid");
  impl_ = std::make_unique<Impl>(mesh, deformed, input, output, options);
}

DisplacementSlabs::~DisplacementSlabs() = default;

std::int64_t DisplacementSlabs::sliceFloats() const {
  return 3 * impl_->output.dims[0] * impl_->output.dims[1];
}

void DisplacementSlabs::rasterize(std::int64_t k0, std::int64_t k1, float* field,
                                  const ProgressFn& progress) const {
  const Impl& r = *impl_;
  raster::checkSlab(k0, k1, r.output);
  const VolumeGeometry &input = r.input, &output = r.output;
  const Eigen::Matrix3d O = output.ijkToRas.block<3, 3>(0, 0), I = input.ijkToRas.block<3, 3>(0, 0);
  const Eigen::Vector3d oo = output.origin(), io = input.origin();
  const Eigen::Matrix3d Iinv = I.inverse();
  const std::int64_t nx = output.dims[0], plane = nx * output.dims[1];
  // Uncovered voxels aim just past the input grid (one voxel centre beyond its nearest face, or
  // nowhere when they already lie a voxel beyond it), so nearest-neighbour resampling gives them
  // background and the field stays within the grid's size: 3D Slicer interpolates a grid
  // transform with a cubic kernel, and a jump of metres beside the skin threw tissue far away.
  auto outside = [&](const Eigen::Vector3d& y) {
    Eigen::Vector3d u = Iinv * (y - io);
    int axis = -1;
    double target = 0, cost = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) {
      const double n = double(input.dims[std::size_t(c)]);
      if (u[c] <= -1 || u[c] >= n) return y;
      const double spacing = I.col(c).norm();
      if ((u[c] + 1) * spacing < cost) cost = (u[c] + 1) * spacing, axis = c, target = -1;
      if ((n - u[c]) * spacing < cost) cost = (n - u[c]) * spacing, axis = c, target = n;
    }
    u[axis] = target;
    return Eigen::Vector3d(I * u + io);
  };
  parallelFor(
      k1 - k0, r.options.threads,
      [&](std::int64_t s0, std::int64_t s1) {
        for (std::int64_t k = k0 + s0; k < k0 + s1; ++k)
          for (std::int64_t j = 0; j < output.dims[1]; ++j)
            for (std::int64_t i = 0; i < nx; ++i) {
              const Eigen::Vector3d y = O * Eigen::Vector3d(double(i), double(j), double(k)) + oo;
              const Eigen::Vector3d d = outside(y) - y;
              float* f = field + 3 * ((k - k0) * plane + j * nx + i);
              f[0] = float(d.x()), f[1] = float(d.y()), f[2] = float(d.z());
            }
      },
      1);
  RasterOptions options = r.options;
  options.progress = progress;
  raster::runScan(
      r.in, r.shell, options, "displacement field", nullptr, raster::frameSign(output),
      [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
          const Eigen::Vector3d& step, std::int32_t) {
        for (std::int64_t i = i0; i <= i1; ++i, p += step) {
          const Eigen::Vector3d d =
              (I * p + io) - (O * Eigen::Vector3d(double(i), double(j), double(k)) + oo);
          float* f = field + 3 * ((k - k0) * plane + j * nx + i);
          f[0] = float(d.x()), f[1] = float(d.y()), f[2] = float(d.z());
        }
      },
      k0, k1);
}

std::vector<float> rasterizeDisplacement(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                         const VolumeGeometry& input, const VolumeGeometry& output,
                                         const RasterOptions& options) {
  const DisplacementSlabs slabs(mesh, deformed, input, output, options);
  std::vector<float> field(static_cast<std::size_t>(3 * output.numVoxels()));
  slabs.rasterize(0, output.dims[2], field.data(), options.progress);
  return field;
}

}  // namespace repose
