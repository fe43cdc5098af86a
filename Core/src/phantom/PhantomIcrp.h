// The phantom's tissues numbered as the ICRP 110 adult reference phantoms number theirs (organ
// IDs of ICRP Publication 110, ../shared/labels/icrp110_organs.csv): skin, muscle, adipose and
// vessels by body region; bones by region and tissue (cortical shell, spongiosa at the ends,
// medullary cavity along the shaft) but not by side; paired organs by side. It lets the rig's
// ICRP convention be tested end to end on a body whose true parts and joints are known.
#pragma once

#include "PhantomBody.h"

#include <Eigen/Core>
#include <cstdint>

namespace repose::phantom {

class IcrpLabeller {
 public:
  explicit IcrpLabeller(const BodyModel& model);
  // The ICRP organ ID of a voxel at p with the phantom's organ label and body part.
  std::uint8_t label(std::uint8_t organ, std::uint8_t part, const Eigen::Vector3d& p) const;

 private:
  // A long bone's axis (proximal joint to distal joint) per side: 0 left, 1 right.
  struct Axis {
    Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::UnitZ();
    double fraction(const Eigen::Vector3d& p) const;  // 0 at `from`, 1 at `to`
  };
  Axis humerus_[2], forearm_[2], femur_[2], tibia_[2];
};

}  // namespace repose::phantom
