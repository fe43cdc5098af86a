// The deformed transfer mesh back to voxels (seed §4.3): for every output voxel, the deformed tet
// containing its centre, the rest position there (barycentric), and the input's value at it.
// In-core, on all cores; slabs of output slices are independent, which the out-of-core path uses.
#pragma once

#include "repose/io/SliceCache.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace repose {

// The output grid for a deformation: the input's axis directions and spacing (or `spacingMm` along
// every axis when > 0), shifted by whole input voxels when the spacing is kept (so an identity or
// a whole-voxel translation maps voxel centres onto voxel centres), and grown to contain every
// deformed vertex plus `marginVoxels`: the body is never clipped. With another spacing no output
// centre lies on an input voxel's face, where nearest-neighbour sampling is a tie that rounding
// noise breaks either way (centres on the input's centres plus whole millimetres met every eighth
// face of 8 mm slices at 1 mm, and a static thin bone changed by 1.5 %): they keep as far from
// the faces as the two spacings allow, and an output voxel a whole number of times smaller than
// the input's subdivides it exactly.
// Throws repose::Error, with the body's span, when the grid would exceed kMaxGridVoxels (2^40, a
// terabyte of bytes: far beyond any budget, so only a handle dragged kilometres away gets there).
constexpr double kMaxGridVoxels = 1099511627776.0;
VolumeGeometry deformedGrid(const VolumeGeometry& input, const Eigen::MatrixX3d& deformed,
                            double spacingMm = 0, int marginVoxels = 1);

// Per tet, one bit per face (bit f: the face opposite vertex f) on the mesh's outer surface: a
// face no other tet shares, unless another such face lies at the same rest place (the two sides of
// a cut made by separateLabels, which are inside the body).
std::vector<std::uint8_t> outerFaces(const TransferMesh& mesh);

// Live slices: a one-voxel-thick RAS-aligned grid on a slice plane at `positionMm` along its
// normal (S for axial, A for coronal, R for sagittal), square pixels, `pixels` across the larger
// in-plane side of the box [lo, hi]. Rasterizing onto it gives the deformed labels on that plane
// only (a view's slice while the cage is dragged).
enum class SliceOrientation { Axial, Coronal, Sagittal };
VolumeGeometry slicePlaneGrid(SliceOrientation orientation, double positionMm,
                              const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int pixels);

struct RasterOptions {
  int threads = 0;
  ProgressFn progress;  // called from worker threads, one call at a time; false cancels
  // Mesh_3 puts the TM's surface only to within a voxel of the label boundary, so some labelled
  // voxel centres (the skin) lie just outside the mesh. Voxels no tet covers but within shellMm
  // outside an outer face take that boundary tet's map, extrapolated. < 0: twice the larger of
  // the input's largest spacing and the mesh's sourceSpacingMm (a mesh built on a coarser proxy
  // is further from the labels); 0: off (only voxels inside tets are written).
  double shellMm = -1;
  const std::vector<std::uint8_t>* outerFaces = nullptr;  // outerFaces(mesh), computed if null
  // The body-part map S the mesh was built from (its tets' labels), on the input's grid. With
  // it a tet's shell does not write a voxel whose rest position is another part's tissue that a
  // rest tet, or the rest shell of that part's own tets, already carries: a limb moved away from
  // the trunk does not extrapolate its boundary tets into the trunk's tissue it rested against
  // (thick slices make the shell wide: 9.6 mm on 4.8 mm slices); and for labels a shell voxel
  // whose rest position is outside the body stays open to the other tets' shells. Costs one
  // coverage scan of the rest mesh and of its outer tets' shells on the input's grid.
  const Volume* restParts = nullptr;
  // The label map G the mesh's whole pieces come from (TransferMesh::rigid holds their ids),
  // on the input's grid. With it each piece also writes its rim: the voxels of its own label
  // within a voxel beyond its tets (Mesh_3 puts a piece's surface only that close), over the
  // soft tissue around it, so a bone or organ beside a bending joint keeps all its voxels.
  const Volume* pieceLabels = nullptr;
  // Labels of pieceLabels meshed in a piece whose id is another label (RigSettings::bonePieces:
  // a bone's cortex and marrow are one piece): label -> piece id. Labels not listed are their
  // own piece's id.
  const std::map<int, int>* bonePieces = nullptr;
  // Labels only (rasterizeLabels, single-layer integer maps): after nearest-neighbour sampling,
  // relabel voxels on the borders between soft labels so each soft label's voxel count comes to
  // the volume the deformation gives it (the sum of the tets' volume ratios over its rest voxels)
  // instead of what sampling a thin structure on a turned grid happens to give
  // (src/raster/LabelVolumeRounding.h). Label 0 and the labels of whole pieces (pieceLabels and
  // bonePieces) are neither taken from nor given to, so the body's outline and the bones stay
  // as sampled. Costs a scan of the rest mesh on the input's grid and a second scan of the
  // voxels on label borders.
  bool preserveLabelVolumes = false;
};

struct RasterReport {
  std::int64_t voxelWrites = 0;  // voxel centres found inside tets (twice where the body folds)
  std::int64_t shellVoxels = 0;  // voxels written from the shell outside the outer faces
  int invertedTets = 0;  // deformed tets turned inside out (a fold): still written, in tet order
  int flatTets = 0;      // deformed tets of zero volume: nothing is inside them
  // Out of core only: voxels per non-zero label of the written output, counted slab by slab so
  // nobody has to read the file back.
  std::map<int, std::int64_t> labelVoxels;
  // RasterOptions::preserveLabelVolumes: voxels relabelled, and per soft label the volume the
  // deformation gives it, in output voxels (the counts it was rounded to).
  std::int64_t roundedVoxels = 0;
  std::map<int, double> labelTargets;
  // Why it was asked for and not done (empty when done or not asked): a map of several layers
  // or of non-integer values, or labels beyond 2^24.
  std::string roundingSkipped;
};

// Labels: each output voxel whose centre lies in a deformed tet (or its shell, see RasterOptions)
// takes the value of `labels` at the nearest input voxel to its rest position (0 beyond the input
// grid); other voxels are 0. Where
// folded tets overlap, a tet of a whole piece (a bone or organ: TransferMesh::rigid) wins over
// soft tissue, and among equals the highest-numbered tet. Every layer of `labels` is mapped; the
// scalar type and label table are kept.
Volume rasterizeLabels(const Volume& labels, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                       const RasterOptions& options = {}, RasterReport* report = nullptr);

// The in-core label scan's step on its own: output slices [k0, k1) of `labels` (in memory) into a
// caller's buffer, voxel for voxel what rasterizeLabels writes there before any label-volume
// rounding (the shell, the pieces' rims and ghosts, soft tissue that does not copy a piece beside
// it), on options.threads threads. Slabs are independent, so a frame too large for memory is
// made slab by slab. Set-up (the scan's input, the shell, the pieces' owners) is done once;
// `labels`, `mesh` and what `options` points to must outlive it. The buffer holds each layer's
// (k1 - k0) slices one after the other (sliceBytes() per slice of all layers).
class LabelSlabs {
 public:
  LabelSlabs(const Volume& labels, const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
             const VolumeGeometry& output, const RasterOptions& options = {});
  ~LabelSlabs();
  LabelSlabs(const LabelSlabs&) = delete;
  LabelSlabs& operator=(const LabelSlabs&) = delete;

  std::int64_t sliceBytes() const;
  // Fills `slab` and adds its counts (voxel writes, shell voxels, layer 0's labelVoxels) to
  // `report`. `progress` gets the fraction of this slab; false cancels.
  void rasterize(std::int64_t k0, std::int64_t k1, void* slab, RasterReport& report,
                 const ProgressFn& progress = {}) const;

 private:
  friend class LabelSlabRounding;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Label-volume rounding (RasterOptions::preserveLabelVolumes) of a frame made slab by slab with
// LabelSlabs: the voxels rasterizeLabels relabels over the whole grid, chosen from every slab's
// counts and candidates (pass 1) and applied to each slab when it is made again or read back
// (pass 2). A single-layer integer map only; others say why in skipped().
class LabelSlabRounding {
 public:
  // The targets (a scan of the rest mesh). Candidates beyond `memoryBytes` are kept in a
  // temporary file (a 0.5 mm frame's label borders hold hundreds of millions).
  explicit LabelSlabRounding(const LabelSlabs& slabs, std::size_t memoryBytes = std::size_t(-1));
  ~LabelSlabRounding();
  LabelSlabRounding(const LabelSlabRounding&) = delete;
  LabelSlabRounding& operator=(const LabelSlabRounding&) = delete;

  // Empty when the map is rounded; else why it is not.
  const std::string& skipped() const;
  // Pass 1, slabs in order from slice 0, each once: slices [k0, k1) as LabelSlabs::rasterize
  // wrote them, with the slices k0 - 1 and k1 as it writes them (null at the grid's faces).
  void addSlab(std::int64_t k0, std::int64_t k1, const void* below, const void* slab,
               const void* above);
  std::size_t candidatesInMemory() const;  // bytes
  std::size_t candidatesOnDisk() const;    // bytes
  // After the last slab: the choice; sets report's roundedVoxels, labelTargets and
  // roundingSkipped as rasterizeLabels does.
  void choose(RasterReport& report);
  // Pass 2: relabels the chosen voxels of slices [k0, k1) in `slab` (after choose()).
  void apply(std::int64_t k0, std::int64_t k1, void* slab) const;
  // The label output voxel `voxel`, sampled as `sampled`, ends with (after choose()).
  std::int64_t finalLabel(std::int64_t voxel, std::int64_t sampled) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The out-of-core path's step on its own: output slices [k0, k1) of the same labels into a
// caller's buffer. Slabs are independent, so callers can write them in any order: the file writer
// (raster/RasterFile.h) in order, `repose warp --mpi` a rank's share of them. Set-up (the deformed
// tets' scan input and the shell) is done once; each slab costs one pass over the tets whose boxes
// meet it. The scan runs on one thread (the cache is not shared).
class LabelSlabRasterizer {
 public:
  LabelSlabRasterizer(SliceCache& input, const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                      const VolumeGeometry& output, const RasterOptions& options = {});
  ~LabelSlabRasterizer();
  LabelSlabRasterizer(const LabelSlabRasterizer&) = delete;
  LabelSlabRasterizer& operator=(const LabelSlabRasterizer&) = delete;

  std::int64_t sliceBytes() const;  // one output slice of the input's scalar type
  // Fills `slab` ((k1 - k0) * sliceBytes() bytes) and adds its counts, labelVoxels included, to
  // `report`. `progress` gets the fraction of this slab; false cancels.
  void rasterize(std::int64_t k0, std::int64_t k1, void* slab, RasterReport& report,
                 const ProgressFn& progress = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Intensities (CT, MR): trilinear interpolation at the rest position, `background` where no tet
// covers the voxel or the rest position is outside the input. Integer types are rounded and
// clamped to their range.
Volume rasterizeImage(const Volume& image, const TransferMesh& mesh,
                      const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                      double background, const RasterOptions& options = {},
                      RasterReport* report = nullptr);

// The inverse map as a displacement field on `output`: per voxel, 3 floats (x fastest, voxels in
// IJK order) in RAS mm from the voxel centre to its rest position, the point of the input the
// rasterizer samples (ITK's output-to-input resampling direction). Voxels no tet (or shell)
// covers point one voxel centre past the input grid's nearest face (or stay put when they lie a
// voxel beyond it already), so nearest-neighbour resampling gives them background as the
// rasterizer does, and no vector is longer than about half the input grid's smallest extent.
std::vector<float> rasterizeDisplacement(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                         const VolumeGeometry& input, const VolumeGeometry& output,
                                         const RasterOptions& options = {});

// The posed image slab by slab: output slices [k0, k1) of what rasterizeImage writes, into a
// caller's buffer ((k1 - k0) * sliceBytes() bytes), on options.threads threads. Set-up (the scan's
// input and shell) is done once; `image`, `mesh` and what `options` points to must outlive it.
class ImageSlabs {
 public:
  ImageSlabs(const Volume& image, const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
             const VolumeGeometry& output, double background, const RasterOptions& options = {});
  ~ImageSlabs();
  ImageSlabs(const ImageSlabs&) = delete;
  ImageSlabs& operator=(const ImageSlabs&) = delete;

  std::int64_t sliceBytes() const;
  // Adds the slab's counts (voxel writes, shell voxels) to `report`; `progress` gets the
  // fraction of this slab, false cancels.
  void rasterize(std::int64_t k0, std::int64_t k1, void* slab, RasterReport& report,
                 const ProgressFn& progress = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The displacement field slab by slab: output slices [k0, k1) of what rasterizeDisplacement
// gives, 3 floats per voxel ((k1 - k0) * sliceFloats() floats), on options.threads threads.
class DisplacementSlabs {
 public:
  DisplacementSlabs(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                    const VolumeGeometry& input, const VolumeGeometry& output,
                    const RasterOptions& options = {});
  ~DisplacementSlabs();
  DisplacementSlabs(const DisplacementSlabs&) = delete;
  DisplacementSlabs& operator=(const DisplacementSlabs&) = delete;

  std::int64_t sliceFloats() const;
  void rasterize(std::int64_t k0, std::int64_t k1, float* slab,
                 const ProgressFn& progress = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// How many deformed tets contain each output voxel centre (UInt8, saturating at 255): 1 inside a
// conforming deformed mesh, 0 outside it, 2 or more where it folds over itself. No shell.
Volume rasterizeCoverage(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                         const VolumeGeometry& output, const RasterOptions& options = {});

}  // namespace repose
