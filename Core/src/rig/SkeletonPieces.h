// The pieces a skeleton given as one label falls into (RigSkeletonSplit.cpp tells them apart):
// its connected components in a box around it, the contacts it has with each other through the
// space between them, and the ways a piece is parted (an erosion and an opening, a cut across
// its axis, a carve by a predicate) or joined.
#pragma once

#include "RigInternal.h"

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

namespace repose::rig {

// A connected piece of the skeleton mask, in the split's local box.
struct Piece {
  std::vector<std::int64_t> voxels;  // G's indices
  V centroid = V::Zero(), axis = V::UnitZ();
  double length = 0, top = -1e300, bottom = 1e300, xMin = 1e300, xMax = -1e300;
  // Its second principal spread over its first: a long bone's is small (its shaft), a scapula's
  // (a plate) or a rib's (an arc) is not.
  double spread = 1;
  BoneKind kind = BoneKind::None;
  int side = 0;
  bool assigned = false;
};

// Two pieces within kNearMm of each other through the space between them, and where.
struct Contact {
  double distance = 1e300;
  V at = V::Zero();
};

constexpr double kNearMm = 20;

class SkeletonPieces {
 public:
  SkeletonPieces(const std::vector<std::int64_t>& voxels, const Grid& grid);

  // Pieces: the mask's 26-connected components. The axial ones (the large ones across the
  // midline) may hold limb bones that touch them (a femoral head in its acetabulum, a humeral head
  // on its glenoid, a scapula on the ribs): one voxel's erosion parts such contacts, and each long
  // lateral part the erosion leaves becomes a piece of its own, grown back over the voxels the
  // erosion took (ring by ring, against the rest of the axial piece). Only those pieces are
  // eroded: a skull or a pelvis one voxel thick on a coarse grid would fall apart.
  void findPieces(double midX, double height);

  // Contacts between pieces: fronts grown from every piece through the space between them
  // (Dijkstra on the 26-neighbourhood in mm, up to kNearMm / 2 from each); where two meet, their
  // distance and the meeting point.
  void findContacts();

  const Contact* contact(int a, int b) const;

  std::vector<Piece>& pieces() { return pieces_; }

  // Parts piece `from` where one voxel's erosion parts it into pieces of at least `minShare` of
  // its voxels each (a humeral head on a glenoid the coarse grid closed); the voxels the erosion
  // took go to the part that reaches them first. Returns the pieces it became (`from` first, the
  // largest part).
  std::vector<int> partPiece(int from, double minShare);

  // Moves every voxel of piece `from` into piece `into` (`from` is left empty).
  void merge(int into, int from);

  // Cuts piece `from` across `u` where it has the fewest voxels between fractions lo and hi of
  // its extent along u; the part beyond becomes a new piece (its index; -1 when none).
  int cutAcross(int from, const V& u, double lo, double hi);

  // Moves the voxels of piece `from` for which `take` holds into a new piece; returns its index
  // (or -1 when none moved).
  int carve(int from, const std::function<bool(std::int64_t)>& take);

 private:
  // The parting of findPieces for one large component across the midline.
  void partAxial(int axial, double midX, double height, int& next);
  // A piece's centroid, principal axis and spread, length and extents.
  void describe(Piece& p) const;
  // A voxel of G's grid in the box, and back.
  std::int64_t local(std::int64_t v) const {
    const auto& d = grid_.dims;
    return (v % d[0] - lo_[0]) +
           box_[0] * (((v / d[0]) % d[1] - lo_[1]) + box_[1] * (v / (d[0] * d[1]) - lo_[2]));
  }

  std::int64_t global(std::int64_t l) const {
    const std::int64_t i = l % box_[0] + lo_[0], j = (l / box_[0]) % box_[1] + lo_[1],
                       k = l / (box_[0] * box_[1]) + lo_[2];
    return i + grid_.dims[0] * (j + grid_.dims[1] * k);
  }

  // Each 26-neighbour of local voxel l inside the box.
  template <class F>
  void neighbours(std::int64_t l, F&& f) const {
    const std::int64_t i = l % box_[0], j = (l / box_[0]) % box_[1], k = l / (box_[0] * box_[1]);
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          if (!di && !dj && !dk) continue;
          const std::int64_t a = i + di, b = j + dj, c = k + dk;
          if (a < 0 || b < 0 || c < 0 || a >= box_[0] || b >= box_[1] || c >= box_[2]) continue;
          f(a + box_[0] * (b + box_[1] * c), di, dj, dk);
        }
  }

  // The 26-connected voxels with `in` set and `own` -1 from start, marked `id` in own.
  std::vector<std::int64_t> floodFrom(std::int64_t start, const std::vector<std::uint8_t>& in,
                                      int id, std::vector<int>& own) const;

  const Grid& grid_;
  std::array<std::int64_t, 3> lo_{}, hi_{}, box_{};
  std::vector<std::uint8_t> mask_;
  std::vector<int> owner_;
  std::vector<Piece> pieces_;
  std::map<std::pair<int, int>, Contact> contacts_;
};

}  // namespace repose::rig
