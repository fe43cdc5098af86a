// `repose warp --mpi` over the ranks of an MPI job (WarpRanks.h), on an MPI session of its own
// (MpiSession.h: only the main thread calls MPI, waits poll so that rank 0 computing the
// deformation keeps its core while the others wait for it).
// Built only where CMake's FindMPI finds MPI (CLI/CMakeLists.txt).
#include "../ArgParser.h"
#include "../WarpRanks.h"
#include "MpiSession.h"

#include "repose/io/GzipPieces.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace repose::cli {
namespace {

using mpi::await;

// Every rank's int64 values, `count` per rank, in rank order.
std::vector<std::int64_t> allGather(MPI_Comm comm, int size,
                                    const std::vector<std::int64_t>& mine) {
  std::vector<std::int64_t> all(mine.size() * std::size_t(size));
  MPI_Request r;
  MPI_Iallgather(mine.data(), static_cast<int>(mine.size()), MPI_INT64_T, all.data(),
                 static_cast<int>(mine.size()), MPI_INT64_T, comm, &r);
  await(r);
  return all;
}

class MpiWarpRanks final : public WarpRanks {
 public:
  ~MpiWarpRanks() override {
    if (file_ != MPI_FILE_NULL) MPI_File_close(&file_);  // every rank unwinds together
  }

  int rank() const override { return rank_; }
  std::int64_t slabs() const override { return slabs_; }
  int size() const override { return size_; }

  void together(const std::function<void()>& step) override { session_.together(step); }

  void broadcast(Eigen::MatrixX3d& matrix) override {
    std::int64_t rows = matrix.rows();
    MPI_Request r;
    MPI_Ibcast(&rows, 1, MPI_INT64_T, 0, comm_, &r);
    await(r);
    if (rank_ != 0) matrix.resize(rows, 3);
    for (int c = 0; c < 3; ++c) {  // a column at a time: contiguous, and a count that fits an int
      MPI_Ibcast(matrix.col(c).data(), static_cast<int>(rows), MPI_DOUBLE, 0, comm_, &r);
      await(r);
    }
  }

  std::string broadcast(const std::string& text) override { return broadcastFrom(0, text); }

  RasterReport writeLabels(LabelSlabRasterizer& slabs, const VolumeGeometry& grid,
                           const NiftiLayout& input, const std::string& path, std::size_t slabBytes,
                           const ProgressFn& progress) override {
    const bool gz = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
    const std::int64_t nz = grid.dims[2], sliceBytes = slabs.sliceBytes();
    // Slabs of whole gzip pieces (the serial writer's pieces; for a .nii they only set the
    // slab's grain), within the budget and under 1 GiB (MPI counts are ints).
    const std::int64_t pieceSlices = niftiGzipPieceSlices(grid, input.type);
    const std::int64_t pieceBytes = pieceSlices * sliceBytes;
    constexpr std::int64_t kMaxSlab = std::int64_t(1) << 30;
    if (pieceBytes > kMaxSlab)
      throw Error(path + ": an output slice of " + std::to_string(sliceBytes) +
                  " bytes is beyond what --mpi writes in one piece (1 GiB)");
    // One slab size for all (the smallest budget's): slab s is the same slices on every rank.
    std::int64_t slabLimit = std::min<std::int64_t>(static_cast<std::int64_t>(slabBytes), kMaxSlab);
    MPI_Request request;
    MPI_Iallreduce(MPI_IN_PLACE, &slabLimit, 1, MPI_INT64_T, MPI_MIN, comm_, &request);
    await(request);
    const std::int64_t slabSlices = pieceSlices * std::max<std::int64_t>(1, slabLimit / pieceBytes);
    const std::int64_t slabCount = (nz + slabSlices - 1) / slabSlices;
    const std::int64_t rounds = (slabCount + size_ - 1) / size_;
    slabs_ = slabCount;

    // The header (one gzip piece of its own) is the same on every rank; rank 0 writes it.
    const std::vector<char> header = niftiHeaderBytes(grid, input.type, input.labels, true);
    const std::string head = gz ? gzipHeaderBytes() + deflatePiece(header.data(), header.size())
                                : std::string(header.begin(), header.end());
    std::uint32_t crc = crc32Of(header.data(), header.size());
    std::uint64_t raw = header.size();
    together([&] {
      const int rc = MPI_File_open(comm_, path.c_str(), MPI_MODE_CREATE | MPI_MODE_WRONLY,
                                   MPI_INFO_NULL, &file_);
      if (rc != MPI_SUCCESS) {
        file_ = MPI_FILE_NULL;
        throw Error(path + ": cannot create the output file (" + mpi::errorText(rc) + ")");
      }
    });
    together([&] {
      if (rank_ == 0) write(path, 0, head.data(), static_cast<std::int64_t>(head.size()), false);
    });
    std::int64_t offset = static_cast<std::int64_t>(head.size());

    RasterReport report;
    std::vector<char> buffer;
    std::string packed;
    for (std::int64_t round = 0; round < rounds; ++round) {
      const std::int64_t slab = round * size_ + rank_;
      const char* data = nullptr;
      std::vector<std::int64_t> mine{0, 0, 0};  // bytes to write, CRC of the raw data, raw bytes
      together([&] {
        if (slab >= slabCount) return;
        const std::int64_t k0 = slab * slabSlices, k1 = std::min(nz, k0 + slabSlices);
        const std::int64_t bytes = (k1 - k0) * sliceBytes;
        buffer.resize(static_cast<std::size_t>(bytes));
        ProgressFn inSlab;
        if (rank_ == 0 && progress)
          inSlab = [&](double f, const std::string& stage) {
            return progress((double(round) + f) / double(rounds), stage);
          };
        slabs.rasterize(k0, k1, buffer.data(), report, inSlab);
        if (!gz) {
          data = buffer.data();
          mine = {bytes, 0, bytes};
          return;
        }
        const std::int64_t pieces = (bytes + pieceBytes - 1) / pieceBytes;
        std::vector<std::string> parts(static_cast<std::size_t>(pieces));
        parallelFor(
            pieces, 0,
            [&](std::int64_t p0, std::int64_t p1) {
              for (std::int64_t p = p0; p < p1; ++p) {
                const std::int64_t n = std::min(pieceBytes, bytes - p * pieceBytes);
                parts[std::size_t(p)] =
                    deflatePiece(buffer.data() + p * pieceBytes, static_cast<std::size_t>(n));
              }
            },
            1);
        packed.clear();
        std::uint32_t c = 0;
        for (std::int64_t p = 0; p < pieces; ++p) {
          const std::int64_t n = std::min(pieceBytes, bytes - p * pieceBytes);
          c = crc32Concat(c, crc32Of(buffer.data() + p * pieceBytes, std::size_t(n)),
                          std::uint64_t(n));
          packed += parts[std::size_t(p)];
        }
        data = packed.data();
        mine = {static_cast<std::int64_t>(packed.size()), c, bytes};
      });
      // Where each rank's bytes go: after the earlier ranks' of this round.
      const std::vector<std::int64_t> all = allGather(comm_, size_, mine);
      std::int64_t at = offset;
      for (int r = 0; r < rank_; ++r) at += all[std::size_t(3 * r)];
      together([&] { write(path, at, data, mine[0], true); });
      for (int r = 0; r < size_; ++r) {
        const auto* v = &all[std::size_t(3 * r)];
        offset += v[0];
        if (v[2] > 0) {
          crc = crc32Concat(crc, static_cast<std::uint32_t>(v[1]), std::uint64_t(v[2]));
          raw += std::uint64_t(v[2]);
        }
      }
    }
    if (gz) {
      const std::string tail = gzipTrailerBytes(crc, raw);
      together([&] {
        if (rank_ == 0) write(path, offset, tail.data(), std::int64_t(tail.size()), false);
      });
    }
    together([&] {
      const int rc = MPI_File_close(&file_);
      file_ = MPI_FILE_NULL;
      if (rc != MPI_SUCCESS)
        throw Error(path + ": closing the file failed (" + mpi::errorText(rc) + ")");
    });
    return gatherReport(report);
  }

 private:
  std::string broadcastFrom(int root, std::string text) {
    return session_.broadcastFrom(root, std::move(text));
  }

  // A collective write (every rank calls it, some with nothing) or rank 0's own.
  void write(const std::string& path, std::int64_t at, const char* data, std::int64_t bytes,
             bool collective) {
    MPI_Request r;
    MPI_Status status;
    void* buffer = const_cast<char*>(data ? data : "");
    const int rc =
        collective
            ? MPI_File_iwrite_at_all(file_, at, buffer, static_cast<int>(bytes), MPI_BYTE, &r)
            : MPI_File_iwrite_at(file_, at, buffer, static_cast<int>(bytes), MPI_BYTE, &r);
    if (rc != MPI_SUCCESS) throw Error(path + ": write failed (" + mpi::errorText(rc) + ")");
    await(r, &status);
    int written = 0;
    MPI_Get_count(&status, MPI_BYTE, &written);
    if (written != bytes)
      throw Error(path + ": write failed (disk full?): " + std::to_string(written) + " of " +
                  std::to_string(bytes) + " bytes written");
  }

  // The counts of every rank on rank 0: the tallies summed (the tet counts are the mesh's, the
  // same everywhere: the largest is kept) and the per-label voxels merged.
  RasterReport gatherReport(const RasterReport& mine) {
    std::vector<std::int64_t> flat{mine.voxelWrites, mine.shellVoxels, mine.invertedTets,
                                   mine.flatTets};
    for (const auto& [value, count] : mine.labelVoxels)
      flat.push_back(value), flat.push_back(count);
    const std::vector<std::int64_t> sizes =
        allGather(comm_, size_, {static_cast<std::int64_t>(flat.size())});
    std::vector<int> counts(static_cast<std::size_t>(size_)), displs(counts.size());
    int total = 0;
    for (int r = 0; r < size_; ++r)
      counts[std::size_t(r)] = static_cast<int>(sizes[std::size_t(r)]),
      displs[std::size_t(r)] = total, total += counts[std::size_t(r)];
    std::vector<std::int64_t> all(static_cast<std::size_t>(total));
    MPI_Request r;
    MPI_Igatherv(flat.data(), static_cast<int>(flat.size()), MPI_INT64_T, all.data(), counts.data(),
                 displs.data(), MPI_INT64_T, 0, comm_, &r);
    await(r);
    RasterReport report;
    if (rank_ != 0) return report;
    for (int k = 0; k < size_; ++k) {
      const std::int64_t* v = all.data() + displs[std::size_t(k)];
      report.voxelWrites += v[0];
      report.shellVoxels += v[1];
      report.invertedTets = std::max(report.invertedTets, static_cast<int>(v[2]));
      report.flatTets = std::max(report.flatTets, static_cast<int>(v[3]));
      for (int i = 4; i + 1 < counts[std::size_t(k)]; i += 2)
        report.labelVoxels[static_cast<int>(v[i])] += v[i + 1];
    }
    return report;
  }

  mpi::Session session_;
  const MPI_Comm comm_ = session_.comm();
  const int rank_ = session_.rank(), size_ = session_.size();
  MPI_File file_ = MPI_FILE_NULL;
  std::int64_t slabs_ = 0;
};

}  // namespace

std::unique_ptr<WarpRanks> makeWarpRanks() {
  return std::make_unique<MpiWarpRanks>();
}

}  // namespace repose::cli
