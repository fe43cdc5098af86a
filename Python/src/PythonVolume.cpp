// Volumes in Python: a repose.Volume's voxels as a numpy array that is a view of the C++ buffer
// (no copy; i fastest, so shape (I, J, K) in Fortran order, as nibabel's arrays), its IJK->RAS
// affine and label table; reading and writing every format Repose knows; the phantom.
#include "PythonCommon.h"

#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/util/Error.h"
#include "repose/util/Memory.h"
#include "repose/volume/Volume.h"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>
#include <optional>
#include <sstream>

namespace repose::python {

namespace {

py::dtype dtypeOf(ScalarType t) {
  switch (t) {
    case ScalarType::UInt8:
      return py::dtype::of<std::uint8_t>();
    case ScalarType::UInt16:
      return py::dtype::of<std::uint16_t>();
    case ScalarType::Int16:
      return py::dtype::of<std::int16_t>();
    case ScalarType::Int32:
      return py::dtype::of<std::int32_t>();
    case ScalarType::Float32:
      break;
  }
  return py::dtype::of<float>();
}

ScalarType scalarTypeOfDtype(const py::dtype& d) {
  if (d.equal(py::dtype::of<std::uint8_t>())) return ScalarType::UInt8;
  if (d.equal(py::dtype::of<std::uint16_t>())) return ScalarType::UInt16;
  if (d.equal(py::dtype::of<std::int16_t>())) return ScalarType::Int16;
  if (d.equal(py::dtype::of<std::int32_t>())) return ScalarType::Int32;
  if (d.equal(py::dtype::of<float>())) return ScalarType::Float32;
  throw py::type_error("voxels of dtype " +
                       py::str(static_cast<py::handle>(d)).cast<std::string>() +
                       " are not kept by Repose (uint8, uint16, int16, int32, float32)");
}

py::list labelsToPython(const LabelTable& table) {
  py::list out;
  for (const Label& l : table.labels()) {
    py::dict d;
    d["value"] = l.value;
    d["name"] = l.name;
    d["color"] = py::make_tuple(l.color[0], l.color[1], l.color[2]);
    d["layer"] = l.layer;
    if (!l.id.empty()) d["id"] = l.id;
    if (!l.tags.empty()) d["tags"] = l.tags;
    out.append(d);
  }
  return out;
}

// A list of dicts as labelsToPython gives, or {value: name}.
LabelTable labelsFromPython(const py::object& labels) {
  LabelTable table;
  if (labels.is_none()) return table;
  if (py::isinstance<py::dict>(labels)) {
    for (const auto& [k, v] : labels.cast<py::dict>()) {
      Label l;
      l.value = k.cast<int>();
      l.name = v.cast<std::string>();
      l.color = LabelTable::defaultColor(l.value, l.name);
      l.colorGenerated = true;
      table.set(l);
    }
    return table;
  }
  for (const py::handle item : labels) {
    const py::dict d = item.cast<py::dict>();
    Label l;
    l.value = d["value"].cast<int>();
    l.name = d.contains("name") ? d["name"].cast<std::string>() : std::string();
    l.color = LabelTable::defaultColor(l.value, l.name);
    l.colorGenerated = true;
    if (d.contains("color")) {
      const auto c = d["color"].cast<std::vector<double>>();
      if (c.size() != 3) throw py::value_error("a label's color is three numbers in [0, 1]");
      l.color = {c[0], c[1], c[2]};
      l.colorGenerated = false;
    }
    if (d.contains("layer")) l.layer = d["layer"].cast<int>();
    if (d.contains("id")) l.id = d["id"].cast<std::string>();
    if (d.contains("tags")) l.tags = d["tags"].cast<std::string>();
    table.set(l);
  }
  return table;
}

Eigen::Matrix4d affineFromPython(const py::object& affine) {
  const auto m = affine.cast<Eigen::Matrix4d>();
  if (!m.allFinite()) throw py::value_error("the affine has non-finite entries");
  return m;
}

// The voxels as a writable numpy view of the volume's buffer, kept alive by `owner`.
py::array arrayView(Volume& v, py::handle owner) {
  const auto s = static_cast<py::ssize_t>(scalarSize(v.scalarType()));
  const auto& d = v.dims();
  std::vector<py::ssize_t> shape{d[0], d[1], d[2]};
  std::vector<py::ssize_t> strides{s, s * d[0], s * d[0] * d[1]};
  if (v.layers() > 1) {
    shape.push_back(v.layers());
    strides.push_back(s * d[0] * d[1] * d[2]);
  }
  return py::array(dtypeOf(v.scalarType()), shape, strides, v.layerData(0), owner);
}

}  // namespace

void bindVolumes(py::module_& m) {
  // dynamic_attr: read_volume keeps what the reader said about the file (read_notes) on the
  // Volume it returns, so a Rig built from it writes them into its reports.
  py::class_<Volume>(m, "Volume", py::dynamic_attr(), R"doc(
A 3D volume in physical space: voxels, the 4x4 IJK->RAS affine (millimetres), and for a label
map its label table. `array` is a numpy view of the voxels (shape (I, J, K), Fortran order, as
nibabel gives them); writing into it changes the volume.)doc")
      .def_static(
          "_from_buffer",
          [](py::array array, const py::object& affine, const py::object& labels, bool labelMap) {
            if (array.ndim() != 3 && array.ndim() != 4)
              throw py::value_error("voxels must be a 3D array (or 4D with layers last)");
            if (!(array.flags() & py::array::f_style))
              throw py::value_error("voxels must be Fortran-ordered (use numpy.asfortranarray)");
            VolumeGeometry g;
            g.dims = {array.shape(0), array.shape(1), array.shape(2)};
            g.ijkToRas = affineFromPython(affine);
            g.validate("array");
            const int layers = array.ndim() == 4 ? int(array.shape(3)) : 1;
            Volume v(g, scalarTypeOfDtype(array.dtype()), layers);
            std::memcpy(v.layerData(0), array.data(), v.byteSize());
            v.labels() = labelsFromPython(labels);
            v.setLabelMap(labelMap);
            return v;
          },
          py::arg("array"), py::arg("affine"), py::arg("labels") = py::none(),
          py::arg("label_map") = false)
      .def_property_readonly(
          "array", [](py::object self) { return arrayView(self.cast<Volume&>(), self); },
          "The voxels: a numpy view (no copy), shape (I, J, K) or (I, J, K, layers).")
      .def_property(
          "affine", [](const Volume& v) { return Eigen::Matrix4d(v.geometry().ijkToRas); },
          [](Volume& v, const py::object& a) {
            VolumeGeometry g = v.geometry();
            g.ijkToRas = affineFromPython(a);
            g.validate("affine");
            v.setGeometry(g);
          },
          "IJK -> RAS millimetres (4x4; NIfTI's convention).")
      .def_property_readonly(
          "shape",
          [](const Volume& v) { return py::make_tuple(v.dims()[0], v.dims()[1], v.dims()[2]); })
      .def_property_readonly(
          "spacing", [](const Volume& v) { return Eigen::Vector3d(v.geometry().spacing()); },
          "Voxel size along I, J, K (mm).")
      .def_property_readonly(
          "origin", [](const Volume& v) { return Eigen::Vector3d(v.geometry().origin()); },
          "RAS position of voxel (0, 0, 0)'s centre (mm).")
      .def_property_readonly(
          "axis_codes", [](const Volume& v) { return v.geometry().axisCodes(); },
          "Orientation codes, e.g. 'RAS' or 'LPS'.")
      .def_property_readonly("dtype", [](const Volume& v) { return dtypeOf(v.scalarType()); })
      .def_property_readonly("layers", &Volume::layers)
      .def_property("is_label_map", &Volume::isLabelMap, &Volume::setLabelMap,
                    "A label map holds discrete labels (posed by nearest neighbour); an image "
                    "holds intensities (trilinear).")
      .def_property(
          "labels", [](const Volume& v) { return labelsToPython(v.labels()); },
          [](Volume& v, const py::object& labels) { v.labels() = labelsFromPython(labels); },
          "The label table: a list of {'value', 'name', 'color', 'layer'} (set from that or "
          "from {value: name}).")
      .def(
          "label_volumes_ml",
          [](const Volume& v) {
            std::map<long long, long long> counts;
            dispatchScalar(v.scalarType(), [&](auto* tag) {
              using T = std::remove_pointer_t<decltype(tag)>;
              const T* p = v.data<T>();
              for (std::int64_t i = 0; i < v.numVoxels(); ++i)
                if (p[i] != T(0)) ++counts[static_cast<long long>(p[i])];
            });
            const Eigen::Vector3d s = v.geometry().spacing();
            const double ml = s.prod() / 1000.0;
            std::map<long long, double> out;
            for (const auto& [label, n] : counts) out[label] = double(n) * ml;
            return out;
          },
          "Volume of every non-zero label of layer 0, in millilitres.")
      .def("copy", [](const Volume& v) { return Volume(v); })
      .def("__repr__", [](const Volume& v) {
        std::ostringstream s;
        const Eigen::Vector3d sp = v.geometry().spacing();
        s << "<repose.Volume " << v.dims()[0] << "x" << v.dims()[1] << "x" << v.dims()[2] << " "
          << scalarTypeName(v.scalarType()) << ", " << sp.x() << "x" << sp.y() << "x" << sp.z()
          << " mm, " << v.geometry().axisCodes() << (v.isLabelMap() ? ", label map, " : ", image")
          << (v.isLabelMap() ? std::to_string(v.labels().size()) + " labels" : std::string())
          << ">";
        return s.str();
      });

  m.def(
      "read_volume",
      [](const std::string& path, py::object progress, std::optional<double> memoryBytes) {
        if (memoryBytes && !(*memoryBytes > 0))
          throw py::value_error("read_volume: memory_bytes must be positive");
        PythonProgress p(std::move(progress));
        ReadOptions o;
        o.progress = p.fn();
        o.memoryLimitBytes = memoryLeftWithin(memoryBytes.value_or(0.0));
        o.budgetHint = "pass a larger memory_bytes= to read_volume";
        std::vector<std::string> notes;  // said as Python warnings once the GIL is back
        o.note = [&notes](const std::string& n) { notes.push_back(n); };
        Volume v;
        try {
          py::gil_scoped_release release;
          v = readVolume(path, o);
        } catch (const Cancelled&) {
          p.rethrow();
          throw;
        }
        for (const std::string& n : notes)
          if (PyErr_WarnEx(PyExc_UserWarning, n.c_str(), 1) < 0) throw py::error_already_set();
        py::object volume = py::cast(std::move(v));
        volume.attr("read_notes") = notes;
        return volume;
      },
      py::arg("path"), py::arg("progress") = py::none(), py::arg("memory_bytes") = py::none(),
      R"doc(Reads a NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), 3D Slicer segmentation
(.seg.nrrd), DICOM SEG file, or a DICOM series folder into RAS millimetres. Raises repose.Error with the command
line's one-line message (the file and the problem). What the reader decided about the file (the
grid a DICOM SEG was placed on, a FRACTIONAL SEG thresholded) is said as a UserWarning and kept
in the Volume's `read_notes` (a list of lines), which a Rig built from it writes into its
reports as "input_notes".

memory_bytes: the budget (default: half the physical memory, as the command line's
--memory). The read may use what the budget leaves beyond the process's resident memory; a file
that needs more is refused with the numbers before anything is allocated.)doc");
  m.def(
      "write_volume",
      [](const Volume& v, const std::string& path, int niftiVersion) {
        WriteOptions o;
        o.niftiVersion = niftiVersion;
        py::gil_scoped_release release;
        writeVolume(v, path, o);
      },
      py::arg("volume"), py::arg("path"), py::arg("nifti_version") = 1,
      "Writes a volume (format by extension; atomically: no partial file on failure).");

  m.def(
      "make_phantom",
      [](double voxelMm, bool armsTouching, bool image, bool armsResting, const py::object& spacing,
         double handGapMm, double forearmGapMm, double vesselMm, bool girdlesTouching) {
        PhantomOptions o;
        o.voxelMm = voxelMm;
        o.armsTouching = armsTouching;
        o.armsResting = armsResting;
        o.handGapMm = handGapMm;
        o.forearmGapMm = forearmGapMm;
        o.limbVesselMm = vesselMm;
        o.girdlesTouching = girdlesTouching;
        if (!spacing.is_none()) o.spacingMm = spacing.cast<Eigen::Vector3d>();
        std::pair<Volume, Volume> maps;
        std::optional<Volume> ct;
        Skeleton skeleton;
        {
          py::gil_scoped_release release;
          const Phantom phantom(o);
          maps = phantom.makeVolumes();
          skeleton = phantom.skeleton();
          if (image) ct = syntheticCT(maps.first);
        }
        py::dict out;
        out["organs"] = std::move(maps.first);
        out["parts"] = std::move(maps.second);
        out["skeleton"] = std::move(skeleton);
        if (ct) out["image"] = std::move(*ct);
        return out;
      },
      py::arg("voxel_mm") = 2.0, py::arg("arms_touching") = false, py::arg("image") = false,
      py::arg("arms_resting") = false, py::arg("spacing_mm") = py::none(),
      py::arg("hand_gap_mm") = 0.0, py::arg("forearm_gap_mm") = 0.0, py::arg("vessel_mm") = 0.0,
      py::arg("girdles_touching") = false,
      R"doc(The synthetic mannequin in memory: {'organs': G, 'parts': S, 'skeleton': Skeleton[,
'image': CT]} (`repose phantom` writes the same to files). arms_resting: the arms against the
trunk, hands on the thighs, thighs touching, with vessels and bone marrow; spacing_mm: (x, y, z)
voxel sizes instead of voxel_mm; hand_gap_mm, forearm_gap_mm (with arms_resting): the hands and
forearms held that far off the thighs and the trunk, as in real reference phantoms; vessel_mm
(with arms_resting): every limb vessel that many mm across, about a voxel as in reference
phantoms (0: anatomical); girdles_touching (with arms_resting): the clavicles meet over the
manubrium, so the two shoulder girdles touch across the sternum.)doc");
}

}  // namespace repose::python
