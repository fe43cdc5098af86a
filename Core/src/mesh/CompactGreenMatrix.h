// The dense Green-coordinate matrix [phi psi] of V_c, stored for the interaction frame.
//
// The frame's product (#V_c rows by ~1500 columns) is memory-bound: at the seed's sizes the
// matrix is 180 MB as float and streaming it takes longer than a frame may. Each coefficient is
// stored as two IEEE half floats, high = half(c) and low = half(c - high), in two separate
// arrays: a preview frame streams only the high halves (half the bytes), an exact product reads
// both (float precision, c = high + low / 2^11). The product is taken on displacements from the
// rest cage, so the preview's ~1e-3 relative coefficient error scales with how far the cage moved,
// not with the body's distance from the origin, and an undeformed cage is reproduced exactly.
#pragma once

#include "repose/util/HugePageAllocator.h"

#include <Eigen/Core>
#include <cstdint>
#include <iosfwd>
#include <vector>

namespace repose {

class CompactGreenMatrix {
 public:
  CompactGreenMatrix() = default;
  // phi: rows by #cage vertices, psi: rows by #cage faces; stored side by side.
  CompactGreenMatrix(const Eigen::MatrixXd& phi, const Eigen::MatrixXd& psi);
  // Room for `rows` rows, filled block by block with setRows (so the double coordinates of the
  // whole V_c never exist at once).
  CompactGreenMatrix(Eigen::Index rows, Eigen::Index vertexCols, Eigen::Index faceCols);
  void setRows(Eigen::Index first, const Eigen::MatrixXd& phi, const Eigen::MatrixXd& psi);

  Eigen::Index rows() const { return rows_; }
  Eigen::Index cols() const { return cols_; }
  Eigen::Index vertexCols() const { return vertexCols_; }
  std::size_t bytes() const {
    return 2 * high_.size() * sizeof(std::uint16_t) + rowScale_.size() * sizeof(double);
  }

  // y = C x for x (cols by 3); preview reads the high halves only. Rows run on `threads`.
  Eigen::MatrixX3d multiply(const Eigen::MatrixX3d& x, bool preview, int threads) const;
  // The same for the listed rows only (all when null), in list order; each row's value is
  // bit-identical to multiply's.
  Eigen::MatrixX3d multiplyRows(const Eigen::MatrixX3d& x, bool preview, int threads,
                                const std::vector<std::int64_t>* rows) const;

  // The stored form, byte for byte (host byte order; GreenCoordinatesFile.h frames it): sizes,
  // row scales, high halves, low halves. readFrom returns false when the stream ends early or the
  // sizes are not those expected (the cage's vertex and face counts), leaving *this unchanged.
  void writeTo(std::ostream& out) const;
  bool readFrom(std::istream& in, Eigen::Index rows, Eigen::Index vertexCols,
                Eigen::Index faceCols);
  // CRC-32 of the stored arrays (zlib's), computed in pieces on `threads`.
  std::uint32_t checksum(int threads) const;

 private:
  Eigen::Index rows_ = 0, cols_ = 0, vertexCols_ = 0, stride_ = 0;  // stride_: cols_ padded to 16
  Eigen::VectorXd rowScale_;  // each row is stored times its scale to stay inside half range
  HugePageVector<std::uint16_t> high_, low_;  // hundreds of MB at the seed's sizes
};

}  // namespace repose
