#include "repose/pose/PoseRig.h"

#include "repose/util/Error.h"

namespace repose {

RigGeometry buildRigGeometry(const Volume& parts, const std::vector<LimbSeparation>& separations,
                             const RigSettings& settings, const ProgressFn& progress) {
  auto scaled = [&](double from, double to) -> ProgressFn {
    if (!progress) return {};
    return
        [=](double f, const std::string& stage) { return progress(from + (to - from) * f, stage); };
  };
  CageOptions co;
  co.targetVertices = settings.cageVertices;
  co.dilateMm = settings.dilateMm;
  co.separations = separations;
  co.threads = settings.threads;
  co.progress = scaled(0, 0.5);
  RigGeometry g;
  g.cage = buildCage(parts, co).mesh;
  TransferMeshOptions to;
  to.sizeMm = settings.meshMm;
  to.progress = scaled(0.5, 1);
  g.mesh = buildTransferMesh(parts, to);
  for (const LimbSeparation& s : separations) separateLabels(g.mesh, s.labelA, s.labelB, s.region);
  reportProgress(progress, 1, "rig built");
  return g;
}

PoseRig::PoseRig(RigGeometry geometry, const Pose& pose, const LabelTable& partLabels, int threads,
                 int jointRings)
    : geometry_(std::move(geometry)), pose_(pose) {
  deformation_ = std::make_unique<CageDeformation>(geometry_.mesh, geometry_.cage, threads);
  handles_ = resolveHandles(pose_, geometry_.cage, geometry_.mesh, partLabels);
  influence_ = computeHandleInfluence(geometry_.mesh, geometry_.cage, handles_, threads,
                                      jointRings >= 0 ? jointRings : pose_.jointRings);
  frames_ = pose_.frames();
}

PoseRig::~PoseRig() = default;

PoseRig::Frame PoseRig::frame(std::size_t index, GreenPrecision precision) const {
  if (index >= frames_.size())
    throw Error("pose " + pose_.name + " has " + std::to_string(frames_.size()) + " frames, not " +
                std::to_string(index + 1));
  Frame f;
  f.name = frames_[index].first;
  f.handles = handles_;
  setMotions(f.handles, frames_[index].second);
  f.cage = poseCage(geometry_.cage, f.handles);
  f.deformed = deformation_->deform(f.cage, influence_, f.handles, &f.tetMaps, precision);
  return f;
}

}  // namespace repose
