// Generated closed triangle meshes for cage tests: subdivided boxes (cube, thin bar) and a
// subdivided octahedron sphere, all with outward-facing triangles.
#pragma once

#include "repose/cage/TriangleMesh.h"

#include <Eigen/Geometry>
#include <map>
#include <vector>

namespace repose::test {

// Axis-aligned box [lo, hi] with each face split into n x n quads (2 triangles each).
inline TriangleMesh boxMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n) {
  std::vector<Eigen::Vector3d> verts;
  std::vector<Eigen::Vector3i> tris;
  std::map<std::tuple<long, long, long>, int> index;  // dedupe shared edge vertices
  auto vertex = [&](const Eigen::Vector3d& t) {       // t in [0,1]^3
    const auto key =
        std::make_tuple(std::lround(t.x() * n), std::lround(t.y() * n), std::lround(t.z() * n));
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    verts.push_back(lo + (hi - lo).cwiseProduct(t));
    return index[key] = static_cast<int>(verts.size()) - 1;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          auto at = [&](int da, int db) {
            Eigen::Vector3d t;
            t[axis] = side;
            t[u] = double(a + da) / n;
            t[v] = double(b + db) / n;
            return vertex(t);
          };
          const int p00 = at(0, 0), p10 = at(1, 0), p11 = at(1, 1), p01 = at(0, 1);
          // (u, v, axis) is right-handed, so u x v points along +axis: flip for the low side.
          if (side == 1) {
            tris.emplace_back(p00, p10, p11);
            tris.emplace_back(p00, p11, p01);
          } else {
            tris.emplace_back(p00, p11, p10);
            tris.emplace_back(p00, p01, p11);
          }
        }
    }
  TriangleMesh m;
  m.vertices.resize(verts.size(), 3);
  for (std::size_t i = 0; i < verts.size(); ++i) m.vertices.row(i) = verts[i];
  m.faces.resize(tris.size(), 3);
  for (std::size_t i = 0; i < tris.size(); ++i) m.faces.row(i) = tris[i];
  return m;
}

// Unit octahedron subdivided `levels` times and projected on a sphere of `radius` around `centre`.
inline TriangleMesh sphereMesh(const Eigen::Vector3d& centre, double radius, int levels) {
  std::vector<Eigen::Vector3d> v = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                    {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::vector<Eigen::Vector3i> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                    {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& t : f) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], ab, ca}, {ab, t[1], bc}, {ca, bc, t[2]}, {ab, bc, ca}});
    }
    f = next;
  }
  TriangleMesh m;
  m.vertices.resize(v.size(), 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    m.vertices.row(i) = centre + radius * v[i].normalized();
  m.faces.resize(f.size(), 3);
  for (std::size_t i = 0; i < f.size(); ++i) m.faces.row(i) = f[i];
  return m;
}

}  // namespace repose::test
