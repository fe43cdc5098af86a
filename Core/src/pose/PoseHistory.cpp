#include "repose/pose/PoseHistory.h"

#include <algorithm>

namespace repose {

namespace {

bool sameRegion(const Region& x, const Region& y) {
  return x.shape == y.shape && x.a == y.a && x.b == y.b;
}

bool sameTransform(const PoseTransform& x, const PoseTransform& y) {
  return x.axis == y.axis && x.angleDeg == y.angleDeg && x.pivot == y.pivot &&
         x.translation == y.translation && x.pivotJoint == y.pivotJoint &&
         x.axisName == y.axisName &&
         std::equal(x.then.begin(), x.then.end(), y.then.begin(), y.then.end(),
                    [](const PoseTurn& a, const PoseTurn& b) {
                      return a.axis == b.axis && a.angleDeg == b.angleDeg &&
                             a.axisName == b.axisName;
                    });
}

}  // namespace

bool samePose(const Pose& a, const Pose& b) {
  if (a.name != b.name || a.description != b.description || a.jointRings != b.jointRings ||
      a.scapulohumeralRhythm != b.scapulohumeralRhythm ||
      a.lumbopelvicRhythm != b.lumbopelvicRhythm || !sameHandleGroups(a, b))
    return false;
  for (std::size_t g = 0; g < a.groups.size(); ++g) {
    const PoseGroup &x = a.groups[g], &y = b.groups[g];
    if (x.follows != y.follows || x.widen != y.widen || !sameTransform(x.transform, y.transform))
      return false;
  }
  const bool keyframes = std::equal(
      a.keyframes.begin(), a.keyframes.end(), b.keyframes.begin(), b.keyframes.end(),
      [](const PoseKeyframe& x, const PoseKeyframe& y) {
        return x.name == y.name &&
               std::equal(x.transforms.begin(), x.transforms.end(), y.transforms.begin(),
                          y.transforms.end(), [](const auto& s, const auto& t) {
                            return s.first == t.first && sameTransform(s.second, t.second);
                          });
      });
  return keyframes &&
         std::equal(a.separations.begin(), a.separations.end(), b.separations.begin(),
                    b.separations.end(), [](const PoseSeparation& x, const PoseSeparation& y) {
                      return x.parts == y.parts && x.partNames == y.partNames &&
                             sameRegion(x.region, y.region);
                    });
}

bool PoseHistory::record(const std::string& target, const Snapshot& before, const Snapshot& after) {
  if (!before || !after || before == after || samePose(*before, *after)) return false;
  if (interacting_ && interactionRecorded_ && !undo_.empty() && undo_.back().target == target)
    undo_.back().after = after;  // the same drag: one step
  else
    undo_.push_back({target, before, after});
  interactionRecorded_ = interacting_;
  redo_.clear();
  return true;
}

void PoseHistory::beginInteraction() {
  interacting_ = true;
  interactionRecorded_ = false;
}

void PoseHistory::endInteraction() {
  interacting_ = false;
  interactionRecorded_ = false;
}

std::optional<PoseHistory::Step> PoseHistory::undo() {
  if (undo_.empty()) return std::nullopt;
  Step step = undo_.back();
  undo_.pop_back();
  redo_.push_back(step);
  return step;
}

std::optional<PoseHistory::Step> PoseHistory::redo() {
  if (redo_.empty()) return std::nullopt;
  Step step = redo_.back();
  redo_.pop_back();
  undo_.push_back(step);
  return step;
}

void PoseHistory::clear() {
  undo_.clear();
  redo_.clear();
  interacting_ = interactionRecorded_ = false;
}

}  // namespace repose
