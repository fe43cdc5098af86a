// Rigging in Python: a user's own segmentation to the body-part map, skeleton and tissue table
// posing needs (`repose rig`), and skeletons read from skeleton.json.
#include "PythonCommon.h"

#include "repose/skeleton/Skeleton.h"
#include "repose/rig/Rig.h"
#include "repose/util/Error.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

namespace repose::python {

void bindRigs(py::module_& m) {
  py::class_<Skeleton>(m, "Skeleton", R"doc(
The body's joints (skeleton.json, as `repose rig` and `repose phantom` write it): each a centre in
RAS mm and its anatomical axes. Pose files name them: "pivot": "elbow_left",
"axis": "elbow_left.flexion".)doc")
      .def_static("read", &readSkeleton, py::arg("path"))
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source) {
            return parseSkeleton(text, source);
          },
          py::arg("text"), py::arg("source") = "skeleton")
      .def("to_json", [](const Skeleton& s) { return skeletonToJson(s); })
      .def_property_readonly("joints",
                             [](const Skeleton& s) {
                               std::vector<std::string> names;
                               for (const SkeletonJoint& j : s.joints) names.push_back(j.name);
                               return names;
                             })
      .def(
          "centre",
          [](const Skeleton& s, const std::string& joint) {
            return Eigen::Vector3d(s.centre(joint, "Skeleton.centre"));
          },
          py::arg("joint"), "The joint's centre (RAS mm).")
      .def(
          "axis",
          [](const Skeleton& s, const std::string& name) {
            return Eigen::Vector3d(s.axis(name, "Skeleton.axis"));
          },
          py::arg("name"), "A joint's axis by \"<joint>.<axis>\", e.g. \"elbow_left.flexion\".")
      .def("__repr__", [](const Skeleton& s) {
        return "<repose.Skeleton " + std::to_string(s.joints.size()) + " joints>";
      });

  py::class_<RigResult>(m, "RiggedBody", R"doc(
What rig_body made of a segmentation: `parts` (the body-part map S), `skeleton`, `tissues_csv`
(the tissue table's text), `report` (rig.json as a dict), `missing` and `warnings` (one line
each); `write(folder)` writes S.nii.gz, skeleton.json, tissues.csv and rig.json as `repose rig`
does.)doc")
      .def_readonly("parts", &RigResult::parts)
      .def_readonly("skeleton", &RigResult::skeleton)
      .def_property_readonly("tissues_csv",
                             [](const RigResult& r) { return tissueTableCsv(r.tissues); })
      .def_readonly("missing", &RigResult::missing)
      .def_readonly("warnings", &RigResult::warnings)
      .def_property_readonly("report",
                             [](const RigResult& r) {
                               return py::module_::import("json").attr("loads")(r.reportJson);
                             })
      .def(
          "write",
          [](const RigResult& r, const std::string& folder, const std::string& input) {
            py::gil_scoped_release release;
            writeRigFolder(r, folder, input);
          },
          py::arg("folder"), py::arg("input") = "G");

  m.def(
      "rig_body",
      [](const Volume& organs, const std::string& labels, const std::string& source, int threads,
         const py::object& progress, const py::object& image) {
        RigOptions o;
        if (!image.is_none()) o.image = &image.cast<const Volume&>();
        o.labels = labels;
        o.source = source;
        o.threads = threads;
        PythonProgress p(progress);
        o.progress = p.fn();
        try {
          py::gil_scoped_release release;
          return rigBody(organs, o);
        } catch (const Cancelled&) {
          p.rethrow();
          throw;
        }
      },
      py::arg("organs"), py::kw_only(), py::arg("labels") = "auto", py::arg("source") = "G",
      py::arg("threads") = 0, py::arg("progress") = py::none(), py::arg("image") = py::none(),
      R"doc(Rigs a segmentation G from its bones (`repose rig`): the body-part map S, the skeleton
and the tissue table. labels: "auto", "phantom", "icrp110", "totalsegmentator" or a CSV path
(label,bone[,side][,name][,density_kg_m3]). image: the scan G was segmented from (a CT or MR
Volume, any grid over the same place), whose outline is the body where G labels organs and bones
but not the tissue between them.)doc");
}

}  // namespace repose::python
