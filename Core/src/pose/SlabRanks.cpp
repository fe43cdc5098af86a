// One process as the only rank of a frame's slabs (SlabRanks.h): each slab is made and used at
// once, in one reused buffer, so a frame made alone holds one slab at a time.
#include "repose/pose/SlabRanks.h"

namespace repose {
namespace {

class OneSlabRank final : public SlabRanks {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void together(const std::function<void()>& step) override { step(); }
  void broadcast(std::vector<std::uint8_t>&) override {}
  std::int64_t minimum(std::int64_t value) override { return value; }
  void pipeline(std::int64_t count, const Make& make, const Use& use) override {
    std::vector<std::uint8_t> bytes;
    for (std::int64_t s = 0; s < count; ++s) {
      make(s, bytes);
      use(s, bytes);
    }
  }
};

}  // namespace

std::unique_ptr<SlabRanks> oneSlabRank() {
  return std::make_unique<OneSlabRank>();
}

}  // namespace repose
