// repose.LiveSession: Core's live session (pose/LiveSession.h) for scripts, as the workbench's
// Logic drives it while a user drags the cage: a rig prepared once, then one warm-started frame
// per change of the pose and the three slices through a point as numpy arrays, each equal to
// that plane of the exported map.
#include "PythonCommon.h"

#include "repose/pose/LiveSession.h"
#include "repose/pose/PoseJob.h"
#include "repose/skeleton/Skeleton.h"

#include <optional>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>

namespace repose::python {

namespace {

struct Live {
  // The session's own copies of G and S, which the job reads by reference: declared first, so
  // they outlive the job and the session (a script may change or drop its Volumes meanwhile).
  std::shared_ptr<const Volume> organs, parts;
  std::unique_ptr<PoseJob> job;
  std::unique_ptr<LiveSession> session;
  Pose pose;  // the last pose set (else the prepared one), its joints resolved: what drag edits
  std::optional<Skeleton> skeleton;

  // The session solves poses whose joint names are resolved (pose/PoseJob.h), as the job's are.
  Pose resolved(Pose p) const {
    resolveJointsWith(p, skeleton ? &*skeleton : nullptr, "");
    return p;
  }
};

const char* const kOrientations[3] = {"axial", "coronal", "sagittal"};

LiveSession::Layer layerOf(const std::string& name) {
  if (name == "labels") return LiveSession::Layer::Labels;
  if (name == "parts") return LiveSession::Layer::Parts;
  if (name == "image") return LiveSession::Layer::Image;
  throw Error("slices: layer must be 'labels', 'parts' or 'image', not '" + name + "'");
}

// A slice (a one-voxel-thick Volume) as a 2D numpy array, rows along the slice's first in-plane
// axis as nibabel orders a volume's first two (a copy: the slice is the session's to replace).
py::array sliceArray(const Volume& v) {
  const auto d = v.dims();
  py::array out;
  dispatchScalar(v.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    py::array_t<T, py::array::f_style> a({d[0], d[1]});
    std::memcpy(a.mutable_data(), v.data<T>(0), std::size_t(d[0] * d[1]) * sizeof(T));
    out = a;
  });
  return out;
}

}  // namespace

void bindLive(py::module_& m) {
  py::class_<Live>(m, "LiveSession", R"doc(
A body rigged once for interaction, then one frame per change of the pose, warm-started from the
last at preview precision, and the views' slices through a point: what the workbench computes
while a user drags the cage, from a script. Preparing (the constructor: cage, transfer mesh,
Green coordinates, factorizations) is the long step; each set_pose or drag is then a few
milliseconds to a fraction of a second. Frames are for one thread at a time.)doc")
      .def(py::init([](const py::object& organsObject, const Volume& parts, const Pose& pose,
                       const py::object& skeleton, const py::object& image, int cageVertices,
                       double dilateMm, int threads, const py::object& progress) {
             const Volume& organs = organsVolume(organsObject);
             PoseJobRequest request;
             if (!skeleton.is_none()) request.skeleton = skeleton.cast<Skeleton>();
             request.settings.cageVertices = cageVertices;
             request.settings.dilateMm = dilateMm;
             request.settings.threads = threads;
             auto live = std::make_unique<Live>();
             live->skeleton = request.skeleton;
             live->organs = std::make_shared<const Volume>(organs);
             live->parts = std::make_shared<const Volume>(parts);
             LiveInputs inputs;
             inputs.labels = live->organs;
             inputs.partLabels = parts.labels();
             inputs.skeleton = request.skeleton;
             if (!image.is_none())
               inputs.image = std::make_shared<const Volume>(image.cast<const Volume&>());
             withProgress(progress, [&](const ProgressFn& fn) {
               live->job =
                   std::make_unique<PoseJob>(pose, *live->organs, *live->parts, std::move(request));
               live->session = std::make_unique<LiveSession>(
                   *live->job, live->job->buildGeometry(fn), std::move(inputs), fn);
               live->session->setParts(live->parts);
               live->pose = live->job->userPose();
               return 0;
             });
             return live;
           }),
           py::arg("organs"), py::arg("parts"), py::arg("pose"), py::kw_only(),
           py::arg("skeleton") = py::none(), py::arg("image") = py::none(),
           py::arg("cage_vertices") = 300, py::arg("dilate_mm") = 10.0, py::arg("threads") = 0,
           py::arg("progress") = py::none(),
           "Prepares the session for the pose's groups (skeleton: the joints a pose names; image: "
           "the body's CT or MR, for the 'image' layer).")
      .def_property_readonly(
          "pose", [](const Live& l) { return l.pose; },
          "A copy of the pose last set (else the one prepared for): edit it and set_pose it.")
      .def(
          "solves",
          [](const Live& l, const Pose& pose) { return l.session->solves(l.resolved(pose)); },
          py::arg("pose"),
          "Whether this session solves frames of the pose (the same groups as the one it was "
          "prepared for; else prepare a new session).")
      .def(
          "set_pose",
          [](Live& l, const Pose& pose, std::size_t frame) {
            const Pose p = l.resolved(pose);
            {
              py::gil_scoped_release release;
              l.session->setPose(p, frame);
            }
            l.pose = p;
          },
          py::arg("pose"), py::arg("frame") = 0,
          "Solves keyframe `frame` of the pose (clamped to its keyframes), warm-started from the "
          "last frame. repose.Error for a pose with other groups; the last frame stays.")
      .def(
          "drag",
          [](Live& l, const std::string& group, std::size_t frame, const py::kwargs& transform) {
            // The edit is Pose.set_transform's (one rule for scripts and the session).
            py::object pose = py::cast(l.pose);
            // Keyframe `frame` of a pose with keyframes, else its base transform (frame 0).
            const py::object keyframe =
                l.pose.keyframes.empty() ? py::object(py::none()) : py::object(py::cast(frame));
            pose.attr("set_transform")(group, py::arg("keyframe") = keyframe, **transform);
            const Pose edited = pose.cast<Pose>();
            {
              py::gil_scoped_release release;
              l.session->setPose(edited, frame);
            }
            l.pose = edited;
          },
          py::arg("group"), py::arg("frame") = 0,
          "Moves a group as a drag does: any of axis=, angle_deg=, pivot=, translation=, then= of "
          "its transform (Pose.set_transform: in keyframe `frame` of a pose with keyframes, else "
          "the base transform), "
          "then solves that frame.")
      .def_property_readonly("has_frame", [](const Live& l) { return l.session->hasFrame(); })
      .def_property_readonly(
          "frame_ms", [](const Live& l) { return l.session->frameMilliseconds(); },
          "How long the last frame's solve took (ms).")
      .def_property_readonly(
          "deformed", [](const Live& l) { return l.session->deformed(); },
          "The frame's transfer-mesh vertices (n x 3, RAS mm).")
      .def_property_readonly(
          "posed_cage", [](const Live& l) { return l.session->posedCage(); },
          "The frame's cage vertices (n x 3, RAS mm).")
      .def_property_readonly(
          "rest_centre", [](const Live& l) { return l.session->restCentre(); },
          "The rest body's centre (RAS mm), where the views start.")
      .def_property_readonly(
          "bounds", [](const Live& l) { return py::make_tuple(l.session->lo(), l.session->hi()); },
          "(lo, hi): the box of the rest and posed body together (RAS mm).")
      .def(
          "slices",
          [](const Live& l, const py::object& point, const std::string& layer, int pixels) {
            const Eigen::Vector3d at =
                point.is_none() ? l.session->restCentre() : point.cast<Eigen::Vector3d>();
            std::vector<LiveSession::SliceRequest> requests;
            const SliceOrientation orientations[3] = {
                SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal};
            // The plane's RAS coordinate: z for axial, y for coronal, x for sagittal.
            const int normal[3] = {2, 1, 0};
            for (int o = 0; o < 3; ++o)
              requests.push_back({layerOf(layer), orientations[o], at[normal[o]], pixels});
            std::vector<LiveSession::Slice> slices;
            {
              py::gil_scoped_release release;
              slices = l.session->slices(requests);
            }
            py::dict out;
            for (int o = 0; o < 3; ++o)
              out[kOrientations[o]] = slices[std::size_t(o)].voxels
                                          ? py::object(sliceArray(*slices[std::size_t(o)].voxels))
                                          : py::object(py::none());
            return out;
          },
          py::arg("point") = py::none(), py::arg("layer") = "labels", py::arg("pixels") = 256,
          "The frame's axial, coronal and sagittal slices through `point` (RAS mm; default the "
          "rest centre) as 2D numpy arrays, {'axial': ..., 'coronal': ..., 'sagittal': ...}, "
          "`pixels` across the body's larger in-plane side; layer 'labels' (G), 'parts' (S) or "
          "'image'. Each is None before a frame, or for an image the session was not given.")
      .def_property_readonly(
          "prediction",
          [](const Live& l) {
            LivePrediction p;
            {
              py::gil_scoped_release release;
              p = l.session->prediction();
            }
            py::dict d;
            d["body_change_percent"] = p.bodyChangePercent;
            d["worst_part"] = p.worstPart;
            d["worst_part_change_percent"] = p.worstPartChangePercent;
            d["dragged_by"] = p.draggedBy;
            d["met"] = p.met;
            d["missed"] = p.missed;
            return d;
          },
          "What the frame predicts of the export's volumes (the frame restored as the export "
          "restores it): body and worst body part change in %, whether the targets are met.")
      .def(
          "group_vertices",
          [](const Live& l, const std::string& group) { return l.session->groupVertices(group); },
          py::arg("group"), "The cage vertices the prepared pose's group moves.");
}

}  // namespace repose::python
