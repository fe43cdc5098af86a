// The module descriptions as tables, written out as XML: each parameter's element (image,
// transform, geometry, file, directory, integer, double, boolean, string-enumeration), its flag,
// channel and texts. Conventions follow Slicer's own CLI modules and Bender's posing modules:
// category first, then title, description, version, contributor, acknowledgements, and the
// parameter groups; inputs and outputs by long flag (never by index), so Slicer passes only the
// ones the user set; results without a flag are return parameters (--returnparameterfile).
#include "SlicerModuleXml.h"

#include "repose/util/XmlText.h"

#include <iostream>
#include <sstream>
#include <vector>

namespace repose::cli {
namespace {

struct Parameter {
  const char* element;     // image, transform, file, ...
  const char* attributes;  // e.g. type="label" fileExtensions=".nrrd"
  const char* name;        // identifier; also the long flag unless `returned`
  const char* label;
  const char* channel;  // "input", "output" or "" (scalars)
  const char* def;      // default ("" for none)
  const char* description;
  bool returned = false;  // a return parameter: channel output, no flag
  std::vector<const char*> choices = {};
};

struct Group {
  const char* label;
  bool advanced;
  std::vector<Parameter> parameters;
};

std::string write(const char* title, const char* description, const std::vector<Group>& groups) {
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<executable>\n"
    << "  <category>Segmentation.Repose</category>\n"
    << "  <title>" << escapeXml(title) << "</title>\n"
    << "  <description><![CDATA[" << description << "]]></description>\n"
    << "  <version>" << REPOSE_VERSION << "</version>\n"
    << "  <documentation-url>docs/SLICER.md</documentation-url>\n"
    << "  <license/>\n"
    << "  <contributor>Repose developers</contributor>\n"
    << "  <acknowledgements><![CDATA[The method: a coarse cage posed by its handles, a transfer "
       "mesh deformed by Green coordinates and a rigidity solve, and each voxel carried by the "
       "tet that holds it (see docs/ARCHITECTURE.md).]]></acknowledgements>\n";
  for (const Group& g : groups) {
    x << "  <parameters" << (g.advanced ? " advanced=\"true\"" : "") << ">\n"
      << "    <label>" << escapeXml(g.label) << "</label>\n";
    for (const Parameter& p : g.parameters) {
      x << "    <" << p.element << (*p.attributes ? " " : "") << p.attributes << ">\n"
        << "      <name>" << p.name << "</name>\n";
      if (!p.returned) x << "      <longflag>" << p.name << "</longflag>\n";
      x << "      <label>" << escapeXml(p.label) << "</label>\n"
        << "      <description><![CDATA[" << p.description << "]]></description>\n";
      if (*p.channel) x << "      <channel>" << p.channel << "</channel>\n";
      if (*p.def) x << "      <default>" << escapeXml(p.def) << "</default>\n";
      for (const char* c : p.choices) x << "      <element>" << c << "</element>\n";
      x << "    </" << p.element << ">\n";
    }
    x << "  </parameters>\n";
  }
  x << "</executable>\n";
  return x.str();
}

// Parameters both modules take, written once.
Parameter labelMapInput(const char* description) {
  return {"image", "type=\"label\"", "input", "Label map G", "input", "", description};
}
Parameter imageInput() {
  return {"image",
          "type=\"scalar\"",
          "image",
          "Image",
          "input",
          "",
          "An optional intensity image on G's grid, posed alongside."};
}
Parameter backgroundOption() {
  return {"string",
          "",
          "background",
          "Image background",
          "",
          "min",
          "The image's value where no tissue is: a number, or min for the image's minimum (air "
          "in a CT)."};
}
Parameter fieldOutput(const char* name) {
  return {"transform",
          "type=\"nonlinear\" fileExtensions=\".nrrd\"",
          name,
          "Displacement field",
          "output",
          "",
          "The posed grid to the input (a resampling transform): resample G through it with "
          "nearest-neighbour interpolation onto the posed label map to reproduce it."};
}
Parameter spacingOption() {
  return {"double",
          "",
          "spacingMm",
          "Output voxel size (mm)",
          "",
          "0",
          "Write the posed maps on an isotropic grid of this size (0: the input's spacing)."};
}
Parameter threadsOption() {
  return {"integer", "", "threads", "Threads", "", "0", "Worker threads (0: all cores)."};
}

// What the module reports back: the report's headline figures (docs/QUALITY.md).
Group resultsGroup() {
  return {"Results",
          false,
          {{"double", "", "bonesMinDice", "Bones min Dice", "output", "",
            "The lowest Dice of a bone against its rigid copy (target: 0.95).", true},
           {"double", "", "bodyVolumeChangePercent", "Body volume change (%)", "output", "",
            "Whole-body volume change of the posed label map (target: within 0.5 %).", true},
           {"double", "", "worstLabelChangePercent", "Worst label change (%)", "output", "",
            "The largest volume change of a label of at least 1000 voxels.", true},
           {"integer", "", "labelsLost", "Labels lost", "output", "",
            "Labels of the input that vanished from the output (target: 0).", true},
           {"string", "", "targetsMissed", "Targets missed", "output", "",
            "The quality targets the frame missed, one after the other (empty: every target "
            "met). The frame is written and loaded either way.",
            true}}};
}

std::string poseXml() {
  std::vector<Group> groups = {
      {"Inputs",
       false,
       {labelMapInput("The segmentation to pose (organs and tissues)."),
        {"image", "type=\"label\"", "parts", "Body-part map S", "input", "",
         "The body parts on G's grid, as `repose rig` makes them: the cage and mesh follow "
         "them."},
        {"file", "fileExtensions=\".json\"", "pose", "Pose file", "input", "",
         "A pose file (*.pose.json, docs/POSES.md): groups of body parts and their rotations, "
         "by named joints."},
        {"file", "fileExtensions=\".json\"", "skeleton", "Skeleton", "input", "",
         "The joints the pose names (skeleton.json, as `repose rig` writes it)."},
        {"file", "fileExtensions=\".csv\"", "tissues", "Tissue table", "input", "",
         "label,name,density_kg_m3,rigid[,bone] (tissues.csv, as `repose rig` writes it)."},
        imageInput(),
        backgroundOption()}},
      {"Outputs",
       false,
       {{"image", "type=\"label\"", "posedLabels", "Posed label map", "output", "",
         "The posed G (the frame chosen below)."},
        {"image", "type=\"label\"", "posedParts", "Posed body-part map", "output", "",
         "The posed S."},
        {"image", "type=\"scalar\"", "posedImage", "Posed image", "output", "",
         "The posed image (with an input image)."},
        fieldOutput("transform"),
        {"integer", "", "frame", "Frame", "", "0",
         "Which frame of a pose with keyframes the outputs above hold (0 = the first)."},
        {"directory", "", "out", "Results folder", "input", "",
         "Optional: every frame's files and report.json (docs/FORMATS.md), kept here."},
        {"string-enumeration",
         "",
         "outputFormat",
         "Label map files",
         "",
         "auto",
         "The label maps in the results folder: NIfTI with a colour table, Slicer "
         "segmentations, both, DICOM SEG, or as the input.",
         false,
         {"auto", "nii.gz", "seg.nrrd", "both", "dcmseg"}}}},
      {"Rig",
       true,
       {{"integer", "", "cageVertices", "Cage vertices", "", "300", "The cage's size."},
        {"double", "", "dilateMm", "Cage distance (mm)", "", "10",
         "How far the cage stands from the body."},
        {"double", "", "meshMm", "Transfer-mesh tet size (mm)", "", "0", "0: 5 % of S's diagonal."},
        {"integer", "", "jointRings", "Joint rings", "", "-1",
         "Widen each joint's transition by this many rings of mesh vertices (-1: the pose "
         "file's)."},
        spacingOption(),
        {"boolean", "", "bendOrgans", "Bend organs", "", "false",
         "Mesh the organs with the soft tissue around them, so a joint's bend may reach them."},
        {"boolean", "", "noAutoSeparate", "No automatic separation", "", "false",
         "Do not cut apart body parts that move with different groups where they touch."},
        {"boolean", "", "keepPockets", "Keep pockets", "", "false",
         "Keep the background pockets a bent joint traps inside the body."},
        {"directory", "", "scene", "Scene folder", "input", "",
         "Reuse the cage and mesh saved here when they match, else save them here."},
        threadsOption()}},
      resultsGroup()};
  return write("Repose: pose a segmentation",
               "Re-poses a segmented whole-body label map by a pose file: a coarse cage around "
               "the body is posed by its handle groups, the tissues follow with their shape and "
               "volume kept, and the posed maps, the displacement field and a quality report are "
               "written at full resolution (repose pose).",
               groups);
}

std::string warpXml() {
  std::vector<Group> groups = {
      {"Inputs",
       false,
       {labelMapInput("The segmentation to pose."),
        {"file", "fileExtensions=\".vtu\"", "mesh", "Transfer mesh", "input", "",
         "The transfer mesh built around G (tm.vtu, as `repose mesh` or `repose pose --scene` "
         "write it)."},
        {"geometry", "type=\"model\" fileExtensions=\".obj\"", "cage", "Cage at rest", "input", "",
         "The cage the mesh was built in (load the scene's cage.vtk as a model)."},
        {"geometry", "type=\"model\" fileExtensions=\".obj\"", "posedCage", "Posed cage", "input",
         "", "The same cage with its vertices moved (the same vertices and faces)."},
        imageInput(),
        backgroundOption()}},
      {"Outputs",
       false,
       {{"image", "type=\"label\"", "out", "Posed label map", "output", "", "The posed G."},
        {"image", "type=\"scalar\"", "imageOut", "Posed image", "output", "",
         "The posed image (with an input image)."},
        fieldOutput("transformOut")}},
      {"Options",
       true,
       {spacingOption(),
        {"double", "", "shellMm", "Shell (mm)", "", "-1",
         "Extrapolate this far outside the mesh (-1: two voxels)."},
        threadsOption()}}};
  return write("Repose: warp by a posed cage",
               "Carries a label map (and an image) through a posed cage at full resolution: the "
               "transfer mesh follows the cage by Green coordinates and a rigidity solve, and "
               "each voxel is taken from where its tet was at rest (repose warp).",
               groups);
}

}  // namespace

bool printSlicerModuleXml(const std::vector<std::string>& args, const std::string& command) {
  if (args.size() != 1 || args[0] != "--xml") return false;
  std::cout << slicerModuleXml(command);
  return true;
}

std::string slicerModuleXml(const std::string& command) {
  if (command == "pose") return poseXml();
  if (command == "warp") return warpXml();
  return "";
}

}  // namespace repose::cli
