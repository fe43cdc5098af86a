// Cage building end to end: field, restricted Delaunay surface, simplification, checks, and how
// much of the body the cage encloses (grid winding numbers over every body voxel).
#include "repose/cage/CageBuilder.h"

#include "CageField.h"
#include "CageSurfaceCgal.h"
#include "repose/cage/GridWinding.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace repose {

bool Region::contains(const Eigen::Vector3d& p) const {
  switch (shape) {
    case Shape::Sphere:
      return (p - a).norm() <= b.x();
    case Shape::OutsideSphere:
      return (p - a).norm() > b.x();
    case Shape::Everywhere:
      return true;
    case Shape::Box:
      break;
  }
  return (p.array() >= a.array()).all() && (p.array() <= b.array()).all();
}

Region Region::parse(const std::string& text) {
  if (text == "everywhere") {
    Region r;
    r.shape = Shape::Everywhere;
    return r;
  }
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw Error("region '" + text + "': expected box:x0,y0,z0,x1,y1,z1 or sphere:x,y,z,r");
  const std::string kind = text.substr(0, colon);
  std::vector<double> values;
  std::stringstream in(text.substr(colon + 1));
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v))
      throw Error("region '" + text + "': '" + item + "' is not a number");
    values.push_back(v);
  }
  Region r;
  if (kind == "box" && values.size() == 6) {
    r.shape = Shape::Box;
    r.a = Eigen::Vector3d(values[0], values[1], values[2])
              .cwiseMin(Eigen::Vector3d(values[3], values[4], values[5]));
    r.b = Eigen::Vector3d(values[0], values[1], values[2])
              .cwiseMax(Eigen::Vector3d(values[3], values[4], values[5]));
  } else if ((kind == "sphere" || kind == "outside") && values.size() == 4 && values[3] > 0) {
    r.shape = kind == "sphere" ? Shape::Sphere : Shape::OutsideSphere;
    r.a = Eigen::Vector3d(values[0], values[1], values[2]);
    r.b = Eigen::Vector3d(values[3], 0, 0);
  } else {
    throw Error("region '" + text +
                "': expected box:x0,y0,z0,x1,y1,z1, sphere:x,y,z,r or outside:x,y,z,r (r > 0), "
                "or everywhere");
  }
  return r;
}

std::string describeCageSetting(int vertices, double dilateMm) {
  char text[64];
  std::snprintf(text, sizeof text, "%d vertices, %g mm", vertices, dilateMm);
  return text;
}

Cage buildCage(const Volume& parts, const CageOptions& options) {
  if (options.targetVertices < 50 || options.targetVertices > 2000)
    throw Error("cage vertex count must be between 50 and 2000, not " +
                std::to_string(options.targetVertices));
  reportProgress(options.progress, 0.0, "cage: working grid");
  Cage cage;
  const cage::CageField field = cage::makeCageField(parts, options, cage.report.bodyVoxels);
  const double w = field.spacing().maxCoeff();
  cage.report.workingVoxelMm = w;

  reportProgress(options.progress, 0.3, "cage: surface mesh");
  const TriangleMesh dense = cage::meshZeroLevelSet(field, 2.0 * w, w);
  cage.report.denseVertices = static_cast<int>(dense.vertices.rows());

  // Garland-Heckbert quadrics first (the method the design names), then Lindstrom-Turk. On
  // creased surfaces (a body cut by the volume border) a collapse sequence can fold the coarse
  // mesh into itself; then the dense surface around the intersecting faces is frozen and the
  // simplification redone, which removes the fold deterministically at the cost of a few vertices.
  reportProgress(options.progress, 0.6, "cage: simplification");
  cage::MeshChecks checks;
  std::vector<bool> frozen(static_cast<std::size_t>(dense.vertices.rows()), false);
  const double freezeRadius = 3 * w;
  for (int round = 0; round < 6; ++round) {
    std::vector<Eigen::Vector3d> sites;
    for (cage::Simplification policy :
         {cage::Simplification::GarlandHeckbert, cage::Simplification::LindstromTurk}) {
      cage.mesh = cage::simplifyMesh(dense, options.targetVertices, policy, frozen);
      checks = cage::checkAndOrient(cage.mesh);
      cage.report.simplification = cage::simplificationName(policy);
      if (checks.closed && checks.manifold && checks.outward && checks.selfIntersectionFree) break;
      if (sites.empty() && checks.closed && checks.manifold)
        sites = cage::selfIntersectionSites(cage.mesh);
    }
    if (checks.selfIntersectionFree || sites.empty()) break;
    for (Eigen::Index v = 0; v < dense.vertices.rows(); ++v)
      for (const Eigen::Vector3d& site : sites)
        if ((dense.vertices.row(v).transpose() - site).norm() < freezeRadius) frozen[v] = true;
    cage.report.frozenVertices = static_cast<int>(std::count(frozen.begin(), frozen.end(), true));
  }
  cage.report.closed = checks.closed;
  cage.report.manifold = checks.manifold;
  cage.report.outward = checks.outward;
  cage.report.selfIntersectionFree = checks.selfIntersectionFree;
  cage.report.vertices = static_cast<int>(cage.mesh.vertices.rows());
  cage.report.faces = static_cast<int>(cage.mesh.faces.rows());
  if (!cage.report.valid()) {
    std::string failed;
    auto add = [&](bool ok, const char* what) {
      if (!ok) failed += (failed.empty() ? "" : ", ") + std::string(what);
    };
    add(checks.closed, "not closed");
    add(checks.manifold, "not manifold");
    add(checks.outward, "not outward-oriented");
    add(checks.selfIntersectionFree, "self-intersecting");
    throw CageCheckError(
        "the cage (" + describeCageSetting(options.targetVertices, options.dilateMm) +
            ") failed its checks: " + failed + "; try more vertices or another dilation",
        failed);
  }

  reportProgress(options.progress, 0.9, "cage: enclosed body");
  const std::vector<std::int8_t> wn =
      windingNumbersOnGrid(cage.mesh, parts.geometry(), options.threads);
  for (std::int64_t n = 0; n < parts.numVoxels(); ++n)
    if (wn[n] >= 1 && parts.valueAsDouble(n) != 0) ++cage.report.enclosedVoxels;
  reportProgress(options.progress, 1.0, "cage");
  return cage;
}

}  // namespace repose
