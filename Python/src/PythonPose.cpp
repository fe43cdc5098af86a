// Poses, rigs and posed frames in Python: pose files read, edited and written; a rig (cage and
// transfer mesh, built or taken from a scene folder) prepared for a pose; each frame posed in
// core (PosedFrame: volumes, field, report) or its labels streamed out of core to a NIfTI file.
#include "PythonCommon.h"

#include "repose/io/MeshIO.h"
#include "repose/io/SliceCache.h"
#include "repose/io/VolumeIO.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseEdit.h"
#include "repose/pose/PoseFrame.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseReport.h"
#include "repose/pose/PoseRig.h"
#include "repose/pose/PoseRun.h"
#include "repose/pose/SceneFolder.h"
#include "repose/raster/RasterFile.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <optional>

namespace repose::python {

namespace {

// A rig as Python holds it: the job (Core's pose-job policy, holding G and S, which the bindings
// keep alive) and the prepared PoseRig.
struct Rig {
  std::unique_ptr<PoseJob> job;
  std::unique_ptr<PoseRig> rig;
  bool sceneReused = false;
  py::object organs, parts;  // the Volumes the job holds, kept alive with the rig
};

// The job's request from the Python layer's arguments: tissues "auto" (beside S, else the
// phantom's when G's labels are the phantom's), a path, a table given as CSV text, or none.
PoseJobRequest requestFrom(const std::string& tissuesPath, bool tissuesAuto,
                           const std::string& tissuesCsv, const py::object& skeleton,
                           const std::string& partsPath) {
  PoseJobRequest request;
  request.partsPath = partsPath;
  request.tissuesPath = tissuesPath;
  request.tissuesAuto = tissuesAuto;
  if (!tissuesCsv.empty()) {
    request.tissues = parseTissueTable(tissuesCsv, "the rigged body's tissues");
    request.tissuesName = "rig_body";
  }
  if (!skeleton.is_none()) request.skeleton = skeleton.cast<Skeleton>();
  return request;
}

// What read_volume's reader said about G (Volume.read_notes; none for a Volume made otherwise),
// for the job's reports ("input_notes", as `repose pose` keeps them). A user may set the
// attribute, so its type is checked with a message that names it.
std::vector<std::string> readNotesOf(const py::object& organs) {
  if (!py::hasattr(organs, "read_notes")) return {};
  const py::object notes = organs.attr("read_notes");
  if (notes.is_none()) return {};
  std::vector<std::string> lines;
  if (py::isinstance<py::str>(notes) || !py::isinstance<py::sequence>(notes))
    throw py::type_error("organs.read_notes: expected a list of str, got " +
                         std::string(py::str(py::type::of(notes).attr("__name__"))));
  for (const py::handle line : notes) {
    if (!py::isinstance<py::str>(line))
      throw py::type_error("organs.read_notes: expected a list of str, holds an item of type " +
                           std::string(py::str(py::type::of(line).attr("__name__"))));
    lines.push_back(line.cast<std::string>());
  }
  return lines;
}

// Each warning of a frame (PoseFrameOptions::warn) as a Python warning, once the GIL is back.
void issueWarnings(const std::string& frame, const std::vector<std::string>& lines) {
  if (lines.empty()) return;
  const py::object warn = py::module_::import("warnings").attr("warn");
  for (const std::string& line : lines)
    warn("frame " + frame + ": " + line, py::arg("stacklevel") = 2);
}

PoseTransform transformFrom(const py::dict& t, const PoseTransform& base) {
  PoseTransform out = base;
  if (t.contains("axis")) out.axis = t["axis"].cast<Eigen::Vector3d>();
  if (t.contains("angle_deg")) out.angleDeg = t["angle_deg"].cast<double>();
  if (t.contains("pivot")) out.pivot = t["pivot"].cast<Eigen::Vector3d>();
  if (t.contains("translation")) out.translation = t["translation"].cast<Eigen::Vector3d>();
  if (!(out.axis.norm() > 0) || !out.axis.allFinite()) throw Error("the rotation axis is zero");
  out.axis.normalize();
  if (t.contains("then")) {  // further turns about the pivot, in order (docs/POSES.md)
    out.then.clear();
    for (const py::handle& item : t["then"].cast<py::list>()) {
      const py::dict turn = item.cast<py::dict>();
      PoseTurn u;
      if (!turn.contains("axis")) throw Error("a turn of \"then\" needs an axis");
      u.axis = turn["axis"].cast<Eigen::Vector3d>();
      if (!(u.axis.norm() > 0) || !u.axis.allFinite()) throw Error("a turn's axis is zero");
      u.axis.normalize();
      if (turn.contains("angle_deg")) u.angleDeg = turn["angle_deg"].cast<double>();
      out.then.push_back(u);
    }
  }
  return out;
}

py::dict transformTo(const PoseTransform& t) {
  py::dict d;
  d["axis"] = Eigen::Vector3d(t.axis);
  d["angle_deg"] = t.angleDeg;
  d["pivot"] = Eigen::Vector3d(t.pivot);
  d["translation"] = Eigen::Vector3d(t.translation);
  py::list then;
  for (const PoseTurn& u : t.then) {
    py::dict turn;
    turn["axis"] = Eigen::Vector3d(u.axis);
    turn["angle_deg"] = u.angleDeg;
    then.append(turn);
  }
  d["then"] = then;
  return d;
}

PoseGroup& groupNamed(Pose& pose, const std::string& name) {
  for (PoseGroup& g : pose.groups)
    if (g.name == name) return g;
  throw Error("pose " + pose.name + ": no group \"" + name + "\"");
}

PoseKeyframe* keyframeNamed(Pose& pose, const py::object& keyframe) {
  if (keyframe.is_none()) return nullptr;
  if (py::isinstance<py::int_>(keyframe)) {
    const int k = keyframe.cast<int>();
    if (k < 0 || std::size_t(k) >= pose.keyframes.size())
      throw Error("pose " + pose.name + " has " + std::to_string(pose.keyframes.size()) +
                  " keyframes, not " + std::to_string(k + 1));
    return &pose.keyframes[std::size_t(k)];
  }
  const std::string name = keyframe.cast<std::string>();
  for (PoseKeyframe& k : pose.keyframes)
    if (k.name == name) return &k;
  throw Error("pose " + pose.name + ": no keyframe \"" + name + "\"");
}

Eigen::MatrixX3d verticesOf(const Eigen::MatrixX3d& v) {
  return v;
}

// A frame's run from the keyword arguments pose_frame and pose_frame_to_folder share.
FrameRun frameRunOf(const Rig& r, const py::object& image, std::optional<double> background,
                    double spacingMm, bool fillPockets, const std::string& labelVolumes,
                    double memoryBytes, const std::string& call) {
  FrameRun run;
  run.image = image.is_none() ? nullptr : &image.cast<const Volume&>();
  run.background = background;
  run.fillPockets = fillPockets;
  if (labelVolumes != "preserve" && labelVolumes != "nearest")
    throw Error("label_volumes must be 'preserve' or 'nearest', not '" + labelVolumes + "'");
  run.preserveLabelVolumes = labelVolumes == "preserve";
  run.spacingMm = spacingMm;
  if (!(memoryBytes >= 0)) throw Error(call + ": memory_bytes must be >= 0");
  run.memoryBudget = memoryBytes;
  run.budgetWhat = call;
  run.budgetHint = "memory_bytes=";
  run.sceneReused = r.sceneReused;
  return run;
}

// Runs the frame as `repose pose` does, its warnings issued as Python warnings once it is done;
// a frame that missed a target is returned all the same, and said so in one line.
FrameOutcome runFrame(const Rig& r, const Volume& organs, const Volume& parts, std::size_t index,
                      FrameRun& run, const py::object& progress) {
  std::vector<std::string> warnings;
  run.warn = [&](const std::string& line) { warnings.push_back(line); };
  FrameOutcome outcome = withProgress(progress, [&](const ProgressFn& fn) {
    run.progress = fn;
    return runPoseFrame(*r.job, *r.rig, index, organs, parts, run);
  });
  if (!outcome.targetsMet) warnings.push_back("it missed its targets: " + outcome.missedLine());
  issueWarnings(outcome.frame.name, warnings);
  return outcome;
}

}  // namespace

// The Volume a rig's `organs` argument holds. It is taken as an object (its read_notes are read
// too), so the type is checked here: pybind's cast error would not say which argument it was.
const Volume& organsVolume(const py::object& organs) {
  if (!py::isinstance<Volume>(organs))
    throw py::type_error("organs: expected a repose.Volume (read_volume, volume_from_array), got " +
                         std::string(py::str(py::type::of(organs).attr("__name__"))));
  return organs.cast<const Volume&>();
}

void bindPoses(py::module_& m) {
  py::class_<Pose>(m, "Pose", R"doc(
A pose file (docs/POSES.md): named handle groups of the cage, each a rigid transform or fixed,
optional keyframes and limb separations. Read with Pose.read or Pose.from_json; edit with
set_transform; write with write.)doc")
      .def_static("read", &readPoseFile, py::arg("path"),
                  "Reads and validates a .pose.json (repose.Error names the field on failure).")
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source) {
            return parsePose(text, source);
          },
          py::arg("text"), py::arg("source") = "pose")
      .def("to_json", &poseToJson)
      .def(
          "write", [](const Pose& p, const std::string& path) { writePoseFile(p, path); },
          py::arg("path"), "Writes the pose (atomically).")
      .def_property_readonly("name", [](const Pose& p) { return p.name; })
      .def_property_readonly(
          "groups",
          [](const Pose& p) {
            std::vector<std::string> names;
            for (const PoseGroup& g : p.groups) names.push_back(g.name);
            return names;
          },
          "The handle groups' names, in order.")
      .def_property_readonly("keyframes",
                             [](const Pose& p) {
                               std::vector<std::string> names;
                               for (const PoseKeyframe& k : p.keyframes) names.push_back(k.name);
                               return names;
                             })
      .def_property_readonly(
          "frame_names",
          [](const Pose& p) {
            std::vector<std::string> names;
            for (const auto& f : p.frames()) names.push_back(f.first);
            return names;
          },
          "One name per frame: the keyframes', or the pose's own.")
      .def(
          "transform",
          [](Pose& p, const std::string& group, const py::object& keyframe) {
            PoseGroup& g = groupNamed(p, group);
            if (PoseKeyframe* k = keyframeNamed(p, keyframe))
              for (const auto& [name, t] : k->transforms)
                if (name == group) return transformTo(t);
            return transformTo(g.transform);
          },
          py::arg("group"), py::arg("keyframe") = py::none(),
          "The group's transform {axis, angle_deg, pivot, translation, then} (in a keyframe, or "
          "the base pose); then: further turns [{axis, angle_deg}] about the pivot, in order.")
      .def(
          "set_transform",
          [](Pose& p, const std::string& group, const py::object& keyframe, const py::kwargs& kw) {
            PoseGroup& g = groupNamed(p, group);
            if (g.fixed) throw Error("pose " + p.name + ": group \"" + group + "\" is fixed");
            PoseKeyframe* k = keyframeNamed(p, keyframe);
            if (!k) {
              g.transform = transformFrom(kw, g.transform);
              return;
            }
            for (auto& [name, t] : k->transforms)
              if (name == group) {
                t = transformFrom(kw, t);
                return;
              }
            k->transforms.emplace_back(group, transformFrom(kw, g.transform));
          },
          py::arg("group"), py::arg("keyframe") = py::none(),
          "Sets any of axis=, angle_deg=, pivot=, translation=, then= of the group's transform (in "
          "a "
          "keyframe by index or name, or the base pose).")
      // Edits by the workbench's rules (Core's pose/PoseEdit.h): the same pose, edited here or
      // in the workbench, gives the same pose file.
      .def_static(
          "new", [](const std::string& name) { return newPose(name); }, py::arg("name") = "pose",
          "A new pose with one group: the fixed rest of the body (as the workbench's New pose).")
      .def(
          "turns",
          [](const Pose& p, const std::string& group, std::size_t frame) {
            py::list out;
            for (const GroupTurn& t : groupTurns(p, group, frame)) {
              py::dict d;
              d["axis_name"] = t.axisName;
              d["axis"] = t.axis;
              d["angle_deg"] = t.angleDeg;
              out.append(d);
            }
            return out;
          },
          py::arg("group"), py::arg("frame") = 0,
          "The group's turns in frame `frame` [{axis_name, axis, angle_deg}]: its first turn, then "
          "each further one (a joint group: rotation, abduction, flexion).")
      .def(
          "set_turn_angle",
          [](Pose& p, const std::string& group, int turn, double angleDeg, std::size_t frame) {
            setGroupTurnAngle(p, group, frame, turn, angleDeg);
          },
          py::arg("group"), py::arg("turn"), py::arg("angle_deg"), py::arg("frame") = 0,
          "Sets the angle of the group's turn `turn` (0: the first) in frame `frame`, as the "
          "workbench's joint sliders do.")
      .def(
          "motion",
          [](const Pose& p, const std::string& group, std::size_t frame) {
            return Eigen::Matrix4d(groupMotion(p, group, frame).matrix());
          },
          py::arg("group"), py::arg("frame") = 0,
          "The group's motion in the world in frame `frame` (4x4, RAS mm): its own transform "
          "carried by the groups it follows.")
      .def(
          "set_motion",
          [](Pose& p, const std::string& group, const Eigen::Matrix4d& world, std::size_t frame) {
            Eigen::Isometry3d m;
            m.matrix() = world;
            setGroupMotion(p, group, frame, m);
          },
          py::arg("group"), py::arg("matrix"), py::arg("frame") = 0,
          "Moves the group so that its motion in the world is `matrix` (4x4 rigid), as a drag of "
          "the workbench's 3D box: a rotation about its own pivot and a translation, after the "
          "groups it follows.")
      .def(
          "add_separation",
          [](Pose& p, const std::string& a, const std::string& b, const std::string& region) {
            addPoseSeparation(p, a, b, region);
          },
          py::arg("part_a"), py::arg("part_b"), py::arg("region"),
          "Adds a separation of two body parts (labels or names of S) within a region "
          "(e.g. 'box:x0,y0,z0,x1,y1,z1').")
      .def(
          "set_joint_group",
          [](Pose& p, const Skeleton& skeleton, const std::string& joint, const py::object& parts) {
            const LabelTable labels =
                parts.is_none() ? LabelTable() : parts.cast<const Volume&>().labels();
            return setJointGroup(p, skeleton, joint, labels);
          },
          py::arg("skeleton"), py::arg("joint"), py::arg("parts") = py::none(),
          "Poses a limb by its joint, as the workbench's joint control: adds (or keeps) the group "
          "named after the joint, turning about each of its axes, in the chain of joint groups. "
          "parts: S, whose label table tells which groups select the joint's parts by label. "
          "Returns the group's name.")
      .def_property_readonly("names_joints", &poseNamesJoints,
                             "Whether a group turns about a joint named in the skeleton.")
      .def(
          "resolve_joints", [](Pose& p, const Skeleton& s) { resolvePoseJoints(p, s); },
          py::arg("skeleton"),
          "Gives the joints the pose names their places and axes from the skeleton (in place).")
      .def("__repr__", [](const Pose& p) {
        return "<repose.Pose " + p.name + ": " + std::to_string(p.groups.size()) + " groups, " +
               std::to_string(std::max<std::size_t>(1, p.keyframes.size())) + " frames>";
      });

  py::class_<PosedFrame>(m, "PosedFrame", R"doc(
One frame posed at full resolution: `organs` (posed G), `parts` (posed S), `image` (or None),
`field` (the displacement field, output -> input, RAS mm, shape (I, J, K, 3)), `report` (the
report.json dict: volumes, masses, distortion, bone rigidity, quality targets).)doc")
      .def_readonly("name", &PosedFrame::name)
      .def_readonly("organs", &PosedFrame::organs)
      .def_readonly("parts", &PosedFrame::parts)
      .def_property_readonly("image",
                             [](const PosedFrame& f) -> py::object {
                               return f.image ? py::cast(*f.image) : py::none();
                             })
      .def_property_readonly("field",
                             [](py::object self) {
                               auto& f = self.cast<PosedFrame&>();
                               const auto& d = f.grid.dims;
                               const py::ssize_t s = sizeof(float);
                               return py::array_t<float>(
                                   {d[0], d[1], d[2], std::int64_t(3)},
                                   {3 * s, 3 * s * d[0], 3 * s * d[0] * d[1], s}, f.field.data(),
                                   self);
                             })
      .def_property_readonly("report",
                             [](const PosedFrame& f) {
                               return py::module_::import("json").attr("loads")(f.reportJson);
                             })
      .def(
          "write",
          [](const PosedFrame& f, const std::string& folder, const std::string& format,
             const std::string& sourceDicom) {
            FrameWriteOptions options;
            options.labelMapFiles = labelMapFilesFor(format, "");
            options.sourceDicom = sourceDicom.empty() ? "" : dicomSourceOf(sourceDicom);
            options.lockFolder = true;  // a `repose pose` writing there refuses, and so does this
            py::gil_scoped_release release;
            writePosedFrame(f, folder, options);
          },
          py::arg("folder"), py::arg("output_format") = "nii.gz", py::arg("source_dicom") = "",
          "Writes the posed maps (output_format 'nii.gz': posed_G.nii.gz and posed_S.nii.gz, "
          "each with a 3D Slicer colour table .ctbl; 'seg.nrrd': Slicer segmentations; "
          "'both'; 'dcmseg': DICOM SEG, with the patient and study of source_dicom, a DICOM "
          "file or folder, when given), posed_image.nii.gz, transform.nrrd and report.json into "
          "the folder, as `repose pose` does. Refused while another Repose run writes into the "
          "folder.");

  py::class_<Rig>(m, "Rig", R"doc(
A body rigged for a pose: the cage and transfer mesh (built from the body-part map S, with the
separations the pose asks for, bones and one-part organs as whole pieces), embedded, the pose's
groups resolved. Each frame of the pose is then a few solves: `deform` gives the posed cage and
mesh, `pose_frame` the full-resolution volumes and report.)doc")
      .def(py::init([](const py::object& organsObject, const Volume& parts, const Pose& named,
                       int cageVertices, double dilateMm, double meshMm,
                       const std::string& tissuesPath, bool tissuesAuto,
                       const std::string& tissuesCsv, bool wholeOrgans, int jointRings, int threads,
                       const py::object& skeleton, bool autoSeparate, const py::object& progress,
                       const std::string& partsPath) {
             const Volume& organs = organsVolume(organsObject);
             // The rule of every front end (pose/PoseRun.h).
             requirePoseableLabels(organs, "the organ map");
             requirePoseableLabels(parts, partsPath.empty() ? "the body-part map" : partsPath);
             PoseJobRequest request =
                 requestFrom(tissuesPath, tissuesAuto, tissuesCsv, skeleton, partsPath);
             request.organsNotes = readNotesOf(organsObject);
             request.settings.cageVertices = cageVertices;
             request.settings.dilateMm = dilateMm;
             request.settings.meshMm = meshMm;
             request.settings.threads = threads;
             request.settings.wholeOrgans = wholeOrgans;
             request.jointRings = jointRings;
             request.autoSeparate = autoSeparate;
             auto r = std::make_unique<Rig>();
             r->job = std::make_unique<PoseJob>(named, organs, parts, std::move(request));
             withProgress(progress, [&](const ProgressFn& fn) {
               r->rig = r->job->makeRig(r->job->buildGeometry(fn), threads);
               return 0;
             });
             return r;
           }),
           py::arg("organs"), py::arg("parts"), py::arg("pose"), py::kw_only(),
           py::arg("cage_vertices") = 300, py::arg("dilate_mm") = 10.0, py::arg("mesh_mm") = 0.0,
           py::arg("_tissues_path") = "", py::arg("_tissues_auto") = true,
           py::arg("_tissues_csv") = "", py::arg("whole_organs") = true,
           py::arg("joint_rings") = -1, py::arg("threads") = 0, py::arg("skeleton") = py::none(),
           py::arg("auto_separate") = true, py::arg("progress") = py::none(),
           py::arg("_parts_path") = "",
           // The job holds G and S: they live as long as the rig.
           py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def_property(
          "volume_restoration", [](const Rig& r) { return r.rig->volumeRestoration(); },
          [](Rig& r, bool on) { r.rig->setVolumeRestoration(on); },
          "Whether each frame relaxes the soft tissue of the joints' bends so every body part "
          "keeps its volume (on by default; `repose pose --no-volume-restoration` turns it off).")
      .def_property_readonly("frame_count", [](const Rig& r) { return r.rig->frameCount(); })
      .def_property_readonly("frame_names",
                             [](const Rig& r) {
                               std::vector<std::string> names;
                               for (std::size_t i = 0; i < r.rig->frameCount(); ++i)
                                 names.push_back(r.rig->frameName(i));
                               return names;
                             })
      .def_property_readonly("pose", [](const Rig& r) { return r.rig->userPose(); })
      .def_property_readonly(
          "cage_vertices", [](const Rig& r) { return verticesOf(r.rig->cage().vertices); },
          "Rest cage vertices (n x 3, RAS mm).")
      .def_property_readonly("cage_faces", [](const Rig& r) { return r.rig->cage().faces; })
      .def_property_readonly(
          "mesh_vertices", [](const Rig& r) { return verticesOf(r.rig->mesh().vertices); },
          "Rest transfer-mesh vertices (n x 3, RAS mm).")
      .def_property_readonly("mesh_tets", [](const Rig& r) { return r.rig->mesh().tets; })
      .def_property_readonly(
          "mesh_tet_parts", [](const Rig& r) { return r.rig->mesh().labels; },
          "Per tet: the body-part label of S it meshes.")
      .def_property_readonly(
          "mesh_tet_pieces",
          [](const Rig& r) {
            const std::vector<int>& rigid = r.rig->mesh().rigid;
            return rigid.empty() ? std::vector<int>(std::size_t(r.rig->mesh().tets.rows()), 0)
                                 : rigid;
          },
          "Per tet: the whole piece (bone, organ) it belongs to, 0 for soft tissue: the piece's "
          "label of G, or for a bone of several labels (cortex, marrow) its smallest.")
      .def_property_readonly(
          "tissue_table", [](const Rig& r) { return r.job->tissues().name; },
          "Which tissue table gives densities and bones ('phantom default', a path, or 'none').")
      .def(
          "deform",
          [](const Rig& r, std::size_t index) {
            PoseRig::Frame f;
            {
              py::gil_scoped_release release;
              f = r.rig->frame(index);
            }
            return py::make_tuple(f.cage, f.deformed);
          },
          py::arg("index") = 0,
          "The frame's posed cage and posed transfer-mesh vertices (RAS mm): the interactive "
          "solve (ARAP + Green coordinates + rigidity), no voxels.")
      .def(
          "pose_frame",
          [](const Rig& r, const Volume& organs, const Volume& parts, std::size_t index,
             const py::object& image, std::optional<double> background, double spacingMm,
             bool fillPockets, const std::string& labelVolumes, double memoryBytes,
             const py::object& progress) {
            // The frame step is Core's (pose/PoseRun.h), as for `repose pose`.
            FrameRun run = frameRunOf(r, image, background, spacingMm, fillPockets, labelVolumes,
                                      memoryBytes, "pose_frame");
            run.budgetHint = "memory_bytes=; or pose_frame_to_folder, which makes it slab by slab";
            return runFrame(r, organs, parts, index, run, progress).frame;
          },
          py::arg("organs"), py::arg("parts"), py::arg("index") = 0, py::kw_only(),
          py::arg("image") = py::none(), py::arg("background") = py::none(),
          py::arg("spacing_mm") = 0.0, py::arg("fill_pockets") = true,
          py::arg("label_volumes") = "preserve", py::arg("memory_bytes") = 0.0,
          py::arg("progress") = py::none(),
          R"doc(Poses frame `index` at full resolution in core: the posed organ and part maps (and
image), the displacement field and the report. spacing_mm: the output voxel size (0: the
input's), e.g. 2 mm for an FDTD grid. label_volumes: "preserve" rounds each soft label to the
volume the deformation gives it, "nearest" leaves plain nearest-neighbour sampling (as
`repose pose --label-volumes`). background: the posed image's value where no tissue is (None: the
image's minimum, air in a CT, as `repose pose --background min`). memory_bytes: the posed
volumes beside what the process holds must fit in it (0: half the physical memory, as
`repose pose --memory`), else an error with the numbers before anything is allocated.)doc")
      .def(
          "pose_frame_to_folder",
          [](const Rig& r, const Volume& organs, const Volume& parts, const std::string& folder,
             std::size_t index, const py::object& image, std::optional<double> background,
             double spacingMm, bool fillPockets, const std::string& labelVolumes,
             const std::string& format, double memoryBytes, const py::object& progress) {
            // The frame step is Core's (pose/PoseRun.h), as for `repose pose`: beyond the budget
            // the frame is made slab by slab into the folder.
            FrameRun run = frameRunOf(r, image, background, spacingMm, fillPockets, labelVolumes,
                                      memoryBytes, "pose_frame_to_folder");
            run.budgetWhat = folder;
            run.labelMapFiles = labelMapFilesFor(format, "");
            run.folder = folder;
            run.write.lockFolder = true;  // a `repose pose` writing there refuses, and so does this
            run.outOfCore = true;
            const FrameOutcome outcome = runFrame(r, organs, parts, index, run, progress);
            return py::module_::import("json").attr("loads")(outcome.reportJson);
          },
          py::arg("organs"), py::arg("parts"), py::arg("folder"), py::arg("index") = 0,
          py::kw_only(), py::arg("image") = py::none(), py::arg("background") = py::none(),
          py::arg("spacing_mm") = 0.0, py::arg("fill_pockets") = true,
          py::arg("label_volumes") = "preserve", py::arg("output_format") = "nii.gz",
          py::arg("memory_bytes") = 0.0, py::arg("progress") = py::none(),
          R"doc(Poses frame `index` at full resolution and writes it into `folder` as `repose pose`
does (the files of PosedFrame.write, and report.json), returning the report. A frame whose posed
volumes exceed memory_bytes (0: half the physical memory) is made slab by slab and written as it
goes: the same files and report (plus "streamed"), whatever its size. output_format: 'nii.gz',
'seg.nrrd', 'both' or 'dcmseg' (refused before the work when its frames would pass DICOM's 4 GiB
of pixel data). Refused while another Repose run writes into the folder.)doc")
      .def(
          "pose_labels_to_file",
          [](const Rig& r, const std::string& organsPath, const std::string& outPath,
             std::size_t index, double memoryBytes, double spacingMm, const py::object& progress) {
            if (!(memoryBytes >= 16.0 * 1048576))
              throw Error("pose_labels_to_file: the memory budget must be at least 16 MiB");
            withProgress(progress, [&](const ProgressFn& fn) {
              const PoseRig::Frame f = r.rig->frame(index);
              SliceCache cache(organsPath, std::size_t(memoryBytes / 2));
              const VolumeGeometry grid =
                  deformedGrid(cache.layout().geometry, f.deformed, spacingMm);
              const std::vector<std::uint8_t> outer = outerFaces(r.rig->mesh());
              RasterOptions ro;
              ro.progress = fn;
              ro.outerFaces = &outer;
              rasterizeLabelsToFile(cache, r.rig->mesh(), f.deformed, grid, outPath,
                                    std::size_t(memoryBytes / 4), ro);
              return 0;
            });
          },
          py::arg("organs_path"), py::arg("out_path"), py::arg("index") = 0, py::kw_only(),
          py::arg("memory_bytes") = 1024.0 * 1048576, py::arg("spacing_mm") = 0.0,
          py::arg("progress") = py::none(),
          R"doc(Out of core: frame `index` of the NIfTI label map at organs_path posed straight
into the NIfTI out_path, slab by slab, holding about memory_bytes (input slices and output
slabs), so label maps larger than memory can be posed.)doc")
      .def(
          "save_scene",
          [](const Rig& r, const std::string& folder, const std::string& organsPath,
             const std::string& partsPath, const std::string& imagePath) {
            writeSceneFolder(folder, *r.rig, r.job->sceneKey(partsPath),
                             {organsPath, partsPath, imagePath}, r.job->settings());
          },
          py::arg("folder"), py::arg("organs_path"), py::arg("parts_path"),
          py::arg("image_path") = "",
          "Writes a scene folder (scene.json, cage.vtk, tm.vtu, the pose) that the workbench "
          "opens and `repose pose --scene` reuses; the inputs are named by path.");

  m.def(
      "_rig_from_scene",
      [](const std::string& folder, const py::object& organsObject, const py::object& partsObject,
         const py::object& pose, int jointRings, int threads, const std::string& tissuesPath,
         bool tissuesAuto) {
        const Volume& organs = organsVolume(organsObject);
        const Volume& parts = partsObject.cast<const Volume&>();
        SceneContents scene = readSceneFolder(folder);
        PoseJobRequest request =
            requestFrom(tissuesPath, tissuesAuto, "", py::none(), scene.inputs.parts);
        request.organsName = scene.inputs.organs;
        request.organsNotes = readNotesOf(organsObject);
        request.settings.threads = threads;
        request.jointRings = jointRings;
        auto r = std::make_unique<Rig>();
        r->sceneReused = true;
        r->organs = organsObject, r->parts = partsObject;
        r->job = std::make_unique<PoseJob>(pose.is_none() ? scene.pose : pose.cast<Pose>(), organs,
                                           parts, std::move(request));
        {
          py::gil_scoped_release release;
          r->rig = r->job->makeRig(std::move(scene.geometry), threads);
        }
        py::dict inputs;
        inputs["organs"] = scene.inputs.organs;
        inputs["parts"] = scene.inputs.parts;
        inputs["image"] = scene.inputs.image;
        return py::make_tuple(std::move(r), inputs);
      },
      py::arg("folder"), py::arg("organs"), py::arg("parts"), py::arg("pose") = py::none(),
      py::arg("joint_rings") = -1, py::arg("threads") = 0, py::arg("_tissues_path") = "",
      py::arg("_tissues_auto") = true);
  m.def(
      "_scene_inputs",
      [](const std::string& folder) {
        const SceneContents scene = readSceneFolder(folder);
        py::dict inputs;
        inputs["organs"] = scene.inputs.organs;
        inputs["parts"] = scene.inputs.parts;
        inputs["image"] = scene.inputs.image;
        return inputs;
      },
      py::arg("folder"));
}

}  // namespace repose::python
