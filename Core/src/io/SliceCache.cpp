#include "repose/io/SliceCache.h"

#include "repose/util/Error.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <vector>

namespace repose {

struct SliceCache::Impl {
  std::string path;      // the user's file, for messages
  std::string dataPath;  // the file read: the user's, or the decompressed copy
  bool temporary = false;
  int fd = -1;
  NiftiLayout layout;
  std::size_t sliceBytes = 0;
  std::int64_t blockSlices = 1;
  std::size_t capacity = 2;  // blocks
  struct Block {
    std::int64_t number = -1;
    std::vector<std::uint8_t> data;
    std::uint64_t used = 0;
  };
  std::vector<Block> blocks;
  std::vector<int> slotOf;  // block number -> slot, or -1
  std::uint64_t clock = 0;
  std::int64_t reads = 0;
  std::int64_t lastBlock = -1;
  int lastSlot = -1;

  ~Impl() {
    if (fd >= 0) ::close(fd);
    if (temporary) std::remove(dataPath.c_str());
  }

  // Streams the gzip file into a fresh temporary file, 4 MiB at a time.
  void decompress() {
    const std::string pattern =
        (std::filesystem::temp_directory_path() / "repose-input-XXXXXX").string();
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    const int out = ::mkstemp(name.data());
    if (out < 0) throwFileError(path, "cannot create a temporary file to decompress into");
    dataPath = name.data();
    temporary = true;
    gzFile in = gzopen(path.c_str(), "rb");
    if (!in) {
      ::close(out);
      throwFileError(path, "cannot open the gzip stream");
    }
    std::vector<char> buffer(4 << 20);
    for (;;) {
      const int n = gzread(in, buffer.data(), static_cast<unsigned>(buffer.size()));
      if (n < 0) {
        gzclose(in);
        ::close(out);
        throwFileError(path, "corrupt gzip data");
      }
      if (n == 0) break;
      for (int done = 0; done < n;) {
        const ssize_t w = ::write(out, buffer.data() + done, static_cast<std::size_t>(n - done));
        if (w <= 0) {
          gzclose(in);
          ::close(out);
          throwFileError(path, "cannot write the decompressed copy (disk full?)");
        }
        done += static_cast<int>(w);
      }
    }
    gzclose(in);
    ::close(out);
  }

  void load(std::int64_t number, Block& b) {
    const std::int64_t first = number * blockSlices;
    const std::int64_t count = std::min(blockSlices, layout.geometry.dims[2] - first);
    b.data.resize(static_cast<std::size_t>(count) * sliceBytes);
    std::size_t done = 0;
    const off_t at = static_cast<off_t>(layout.dataOffset + first * std::int64_t(sliceBytes));
    while (done < b.data.size()) {
      const ssize_t r =
          ::pread(fd, b.data.data() + done, b.data.size() - done, at + static_cast<off_t>(done));
      if (r <= 0) throwFileError(path, "cannot read voxels (file truncated or unreadable)");
      done += static_cast<std::size_t>(r);
    }
    b.number = number;
    ++reads;
  }
};

SliceCache::SliceCache(const std::string& path, std::size_t budgetBytes)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = m.dataPath = path;
  m.layout = readNiftiLayout(path);
  const auto& d = m.layout.geometry.dims;
  m.sliceBytes = static_cast<std::size_t>(d[0] * d[1]) * scalarSize(m.layout.type);
  if (budgetBytes < 2 * m.sliceBytes)
    throwFileError(path, "a memory budget of " + std::to_string(budgetBytes) +
                             " bytes cannot hold two of its slices (" +
                             std::to_string(2 * m.sliceBytes) + " bytes)");
  if (m.layout.gzip) m.decompress();
  m.fd = ::open(m.dataPath.c_str(), O_RDONLY);
  if (m.fd < 0) throwFileError(path, "cannot open for reading");
  const std::int64_t need = m.layout.dataOffset + d[2] * std::int64_t(m.sliceBytes);
  if (static_cast<std::int64_t>(std::filesystem::file_size(m.dataPath)) < need)
    throwFileError(path, "file is truncated: its voxels need " + std::to_string(need) + " bytes");
  // About 16 blocks in the budget; whole slices each.
  m.blockSlices = std::max<std::int64_t>(
      1, std::min<std::int64_t>(d[2], std::int64_t(budgetBytes / 16 / m.sliceBytes)));
  m.capacity = std::max<std::size_t>(2, budgetBytes / (m.blockSlices * m.sliceBytes));
  m.slotOf.assign(static_cast<std::size_t>((d[2] + m.blockSlices - 1) / m.blockSlices), -1);
}

SliceCache::~SliceCache() = default;

const NiftiLayout& SliceCache::layout() const {
  return impl_->layout;
}
std::int64_t SliceCache::blockReads() const {
  return impl_->reads;
}
std::size_t SliceCache::blockBytes() const {
  return impl_->blockSlices * impl_->sliceBytes;
}

const void* SliceCache::slice(std::int64_t k) {
  Impl& m = *impl_;
  const std::int64_t number = k / m.blockSlices;
  if (number != m.lastBlock) {
    int slot = m.slotOf[static_cast<std::size_t>(number)];
    if (slot < 0) {
      if (m.blocks.size() < m.capacity) {
        m.blocks.emplace_back();
        slot = static_cast<int>(m.blocks.size() - 1);
      } else {
        slot = 0;
        for (std::size_t s = 1; s < m.blocks.size(); ++s)
          if (m.blocks[s].used < m.blocks[slot].used) slot = static_cast<int>(s);
        m.slotOf[static_cast<std::size_t>(m.blocks[slot].number)] = -1;
      }
      m.load(number, m.blocks[slot]);
      m.slotOf[static_cast<std::size_t>(number)] = slot;
    }
    m.lastBlock = number;
    m.lastSlot = slot;
  }
  Impl::Block& b = m.blocks[static_cast<std::size_t>(m.lastSlot)];
  b.used = ++m.clock;
  return b.data.data() + static_cast<std::size_t>(k - number * m.blockSlices) * m.sliceBytes;
}

}  // namespace repose
