// The MRML conventions followed (Slicer/Slicer, Libs/MRML/Core): each node is an element named by
// its tag (vtkMRML*Node::GetNodeTagName) with id, name and the base attributes
// (vtkMRMLNode::WriteXML); references="role:id;..." with the roles in alphabetical order
// (NodeReferences is a std::map); storage nodes carry a URL-encoded fileName
// (vtkMRMLNode::URLEncodeString), relative to the scene's folder (vtkMRMLStorageNode::WriteXML);
// model storage says coordinateSystem="RAS" (the files say SPACE=RAS too, which wins:
// vtkMRMLModelStorageNode.cxx); display nodes name their colour table by colorNodeID, not by a
// reference.
#include "repose/pose/SlicerSceneMrml.h"

#include "repose/util/XmlText.h"

#include <filesystem>
#include <sstream>
#include <vector>

namespace repose {
namespace {

namespace fs = std::filesystem;

// vtkMRMLNode::URLEncodeString: %, space, ', <, >, " (and XML's & for our own safety).
std::string urlEncode(const std::string& text) {
  std::string out;
  for (char c : text) switch (c) {
      case '%':
        out += "%25";
        break;
      case ' ':
        out += "%20";
        break;
      case '\'':
        out += "%27";
        break;
      case '>':
        out += "%3E";
        break;
      case '<':
        out += "%3C";
        break;
      case '"':
        out += "%22";
        break;
      case '&':
        out += "%26";
        break;
      default:
        out += c;
    }
  return out;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string stem(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  for (const char* ext : {".seg.nrrd", ".nii.gz", ".nii", ".nrrd", ".nhdr", ".vtk", ".vtu"})
    if (endsWith(name, ext)) return name.substr(0, name.size() - std::string(ext).size());
  return name;
}

class SceneWriter {
 public:
  explicit SceneWriter(fs::path folder) : folder_(fs::absolute(std::move(folder))) {}

  // A file's name as the scene stores it: relative to the scene's folder, as Slicer's own writer
  // stores every file (vtksys::SystemTools::RelativePath from the scene's root directory), so the
  // results, the scene folder and the input keep working when moved together.
  std::string fileName(const std::string& path) const {
    const fs::path p = fs::absolute(path).lexically_normal();
    const fs::path rel = p.lexically_relative(folder_.lexically_normal());
    return urlEncode(rel.empty() ? p.generic_string() : rel.generic_string());
  }

  void node(const std::string& tag, const std::string& id, const std::string& name, bool hidden,
            const std::string& extra) {
    out_ << " <" << tag << "\n  id=\"" << id << "\" name=\"" << escapeXml(name)
         << "\" hideFromEditors=\"" << (hidden ? "true" : "false")
         << "\" selectable=\"true\" selected=\"false\"" << extra << " ></" << tag << ">\n";
  }

  // Storable and displayable: a storage node, a display node and the data node referencing them.
  void storable(const std::string& tag, const std::string& cls, int n, const std::string& name,
                const std::string& storageTag, const std::string& storageExtra,
                const std::string& file, const std::string& displayTag,
                const std::string& displayExtra, const std::string& dataExtra) {
    const std::string idx = std::to_string(n);
    const std::string storageId = "vtkMRML" + storageTag + "Node" + idx;
    node(storageTag, storageId, storageTag, true,
         " fileName=\"" + fileName(file) +
             "\" useCompression=\"1\" readState=\"0\" writeState=\"0\"" + storageExtra);
    std::string references;
    if (!displayTag.empty()) {
      const std::string displayId = "vtkMRML" + displayTag + "Node" + idx;
      node(displayTag, displayId, displayTag, true,
           " visibility=\"true\" visibility2D=\"true\" visibility3D=\"true\"" + displayExtra);
      references += "display:" + displayId + ";";
    }
    references += "storage:" + storageId + ";";  // roles in alphabetical order
    node(tag, "vtkMRML" + cls + "Node" + idx, name, false,
         " references=\"" + references + "\" userTags=\"\"" + dataExtra);
  }

  std::string colorNodeId = "vtkMRMLColorTableNodeFileGenericColors.txt";  // Slicer's default
  std::ostringstream out_;

 private:
  fs::path folder_;
};

}  // namespace

std::string formatSlicerScene(const SlicerSceneFiles& files, const std::string& sceneFolder) {
  SceneWriter w(sceneFolder);
  w.out_ << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         << "<MRML version=\"Slicer 5.8.1 33241\" userTags=\"\">\n";
  int n = 1;
  if (!files.colorTable.empty()) {
    w.colorNodeId = "vtkMRMLColorTableNode" + std::to_string(n);
    w.node("ColorTableStorage", "vtkMRMLColorTableStorageNode" + std::to_string(n),
           "ColorTableStorage", true,
           " fileName=\"" + w.fileName(files.colorTable) +
               "\" useCompression=\"1\" readState=\"0\" writeState=\"0\"");
    w.node("ColorTable", w.colorNodeId, stem(files.colorTable), false,
           " references=\"storage:vtkMRMLColorTableStorageNode" + std::to_string(n) +
               ";\" userTags=\"\"");
    ++n;
  }
  auto labelMap = [&](const std::string& path) {
    if (endsWith(path, ".seg.nrrd")) {
      w.storable("Segmentation", "Segmentation", n++, stem(path), "SegmentationStorage",
                 " CropToMinimumExtent=\"false\"", path, "SegmentationDisplay",
                 " Visibility2DFill=\"true\" Visibility2DOutline=\"true\" Opacity3D=\"1\" "
                 "Opacity2DFill=\"0.5\" Opacity2DOutline=\"1\"",
                 " SourceRepresentationName=\"Binary labelmap\"");
    } else {
      w.storable("LabelMapVolume", "LabelMapVolume", n++, stem(path), "VolumeArchetypeStorage",
                 " centerImage=\"0\" UseOrientationFromFile=\"1\"", path, "LabelMapVolumeDisplay",
                 " colorNodeID=\"" + w.colorNodeId + "\"", "");
    }
  };
  if (!files.inputLabels.empty()) labelMap(files.inputLabels);
  if (!files.posedLabels.empty()) labelMap(files.posedLabels);
  if (!files.transform.empty())
    w.storable("GridTransform", "GridTransform", n++, stem(files.transform), "TransformStorage",
               " preferITKv3CompatibleTransforms=\"false\"", files.transform, "", "", "");
  for (const auto& [path, colour] :
       {std::pair{files.cage, "0.9 0.75 0.2"}, std::pair{files.transferMesh, "0.5 0.7 0.9"}})
    if (!path.empty())
      w.storable("Model", "Model", n++, stem(path), "ModelStorage", " coordinateSystem=\"RAS\"",
                 path, "ModelDisplay",
                 std::string(" color=\"") + colour + "\" opacity=\"0.4\" representation=\"1\"", "");
  w.out_ << "</MRML>\n";
  return w.out_.str();
}

}  // namespace repose
