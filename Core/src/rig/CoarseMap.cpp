// Recognising a coarse map: by name, else by shape. The body's outline is the largest label and
// spans every labelled voxel's box; the skeleton spans most of the body's height and width yet
// touches the background almost nowhere (at most 3 % of its voxels: a sinus or an ear canal left
// unlabelled, a hand on the grid's edge; skin and fat, as long and as wide, lie on the outside).
#include "CoarseMap.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <sstream>

namespace repose::rig {
namespace {

std::string lowered(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

struct Shape {
  std::int64_t voxels = 0, outside = 0;  // outside: voxels with a face on the background
  std::array<std::int64_t, 3> lo{INT64_MAX, INT64_MAX, INT64_MAX}, hi{-1, -1, -1};
};

}  // namespace

std::optional<CoarseMap> recogniseCoarseMap(const Volume& organs, const std::vector<int>& labels) {
  CoarseMap m;
  // By name.
  for (const int v : labels) {
    const Label* l = organs.labels().find(v);
    const std::string n = l ? lowered(l->name) : "";
    if (n == "skeleton" || n == "bone" || n == "bones" || n == "skeletal system")
      m.skeleton = m.skeleton ? -1 : v;
    if (n == "body" || n == "body outline" || n == "soft tissue" || n == "soft_tissue")
      m.body = m.body ? -1 : v;
  }
  if (m.skeleton > 0) {
    if (m.body < 0) m.body = 0;
    std::ostringstream s;
    s << "auto: label " << m.skeleton << " is named as a skeleton";
    if (m.body > 0) s << ", label " << m.body << " as the body";
    m.how = s.str();
    return m;
  }
  // By shape: a few unnamed labels only.
  if (labels.size() > 12) return std::nullopt;
  for (const int v : labels)
    if (const Label* l = organs.labels().find(v); l && !l->name.empty()) return std::nullopt;
  std::map<int, Shape> shape;
  const auto& d = organs.geometry().dims;
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  bool integral = false;
  dispatchScalar(organs.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      integral = true;
      const T* g = organs.data<T>();
      for (std::int64_t k = 0; k < d[2]; ++k)
        for (std::int64_t j = 0; j < d[1]; ++j)
          for (std::int64_t i = 0; i < d[0]; ++i) {
            const std::int64_t n = i + d[0] * (j + d[1] * k);
            if (g[n] <= 0) continue;
            Shape& s = shape[int(g[n])];
            ++s.voxels;
            const std::int64_t ijk[3] = {i, j, k};
            bool out = false;
            for (int a = 0; a < 3; ++a) {
              s.lo[a] = std::min(s.lo[a], ijk[a]), s.hi[a] = std::max(s.hi[a], ijk[a]);
              for (int t : {-1, 1}) {
                const std::int64_t m2 = ijk[a] + t;
                out = out || m2 < 0 || m2 >= d[a] || g[n + t * step[a]] == 0;
              }
            }
            s.outside += out;
          }
    }
  });
  if (!integral || shape.size() < 2) return std::nullopt;
  Shape all;
  int largest = 0;
  for (const auto& [v, s] : shape) {
    all.voxels += s.voxels;
    for (int a = 0; a < 3; ++a)
      all.lo[a] = std::min(all.lo[a], s.lo[a]), all.hi[a] = std::max(all.hi[a], s.hi[a]);
    if (!largest || s.voxels > shape[largest].voxels) largest = v;
  }
  auto extent = [](const Shape& s, int a) { return double(s.hi[a] - s.lo[a] + 1); };
  const Shape& body = shape[largest];
  for (int a = 0; a < 3; ++a)
    if (extent(body, a) < 0.9 * extent(all, a)) return std::nullopt;
  // The body's long axis: the grid's axis along which it is longest (its height).
  int up = 0;
  for (int a = 1; a < 3; ++a)
    if (extent(all, a) * organs.geometry().spacing()[a] >
        extent(all, up) * organs.geometry().spacing()[up])
      up = a;
  std::vector<int> skeletons;
  for (const auto& [v, s] : shape) {
    if (v == largest) continue;
    bool spans = extent(s, up) >= 0.8 * extent(all, up);
    for (int a = 0; a < 3; ++a)
      if (a != up) spans = spans && extent(s, a) >= 0.3 * extent(all, a);
    const double share = double(s.voxels) / double(all.voxels);
    if (spans && share > 0.02 && share < 0.4 && s.outside <= s.voxels * 3 / 100)
      skeletons.push_back(v);
  }
  if (skeletons.size() != 1) return std::nullopt;
  m.body = largest;
  m.skeleton = skeletons[0];
  std::ostringstream s;
  s << "auto: a coarse map of " << labels.size() << " unnamed labels: " << m.body
    << " the body (the largest, spanning every label), " << m.skeleton
    << " the skeleton (head to feet inside the body, "
    << std::lround(100.0 * double(shape[m.skeleton].voxels) / double(all.voxels)) << " % of it)";
  m.how = s.str();
  return m;
}

}  // namespace repose::rig
