// scene.json, the document of a Repose scene folder (docs/FORMATS.md, "Scene folders"): the names
// its writers and readers share. Core's scene folders (`repose pose --scene`, Python's
// load_scene) and the MRML scene (the workbench and the Slicer module) write and read the same
// document through these names only, so neither can rename a node class or a field the other
// still reads. This header is the whole module (the INTERFACE library ReposeSceneSchema): no
// dependency, so the MRML layer takes it without taking Core.
#pragma once

namespace repose::scene_schema {

inline constexpr char kDocument[] = "scene.json";  // in the scene folder
inline constexpr char kFormatKey[] = "format";
inline constexpr char kFormat[] = "repose-scene";
inline constexpr char kVersionKey[] = "version";
inline constexpr int kVersion = 2;
inline constexpr char kNodes[] = "nodes";  // an array of node objects
// The rig key a folder's cage and mesh were built for (Core's SceneFolder.h: sceneRigKey); a
// scene the workbench saved has none, so `repose pose --scene` builds the rig again there.
inline constexpr char kBuiltFor[] = "built_for";
// File name (as its node names it) -> "SIZE:CRC32" (decimal size, hex CRC-32 of the bytes) of the
// rig files the command line wrote, so a file replaced or edited by hand later is noticed; a
// scene the workbench saved has none, and its files are taken as they are.
inline constexpr char kFileStamps[] = "file_stamps";
// The module's parameter node (vtkMRMLReposeParametersNode's JSON: the panel's inputs, settings
// and results), so a scene the workbench saved reopens with the panel as it was. Core's scene
// folders neither write nor read it.
inline constexpr char kParameters[] = "parameters";

// Members of every node. Files are relative to the scene folder unless absolute.
inline constexpr char kClass[] = "class";
inline constexpr char kId[] = "id";
inline constexpr char kName[] = "name";
inline constexpr char kReferences[] = "references";  // role -> node id

// Reference roles.
inline constexpr char kSegmentationRole[] = "segmentation";
inline constexpr char kCageRole[] = "cage";
inline constexpr char kTransferMeshRole[] = "transfer_mesh";

// The node classes and their fields.
namespace segmentation {
inline constexpr char kClassName[] = "vtkMRMLReposeSegmentationNode";
inline constexpr char kLabelMapFile[] = "LabelMapFileName";        // G
inline constexpr char kBodyPartMapFile[] = "BodyPartMapFileName";  // S
inline constexpr char kImageFile[] = "ImageFileName";              // optional, on G's grid
inline constexpr char kSkeleton[] = "SkeletonJSON";                // the rig's joints, as text
// A posed segmentation's export: its report.json (text) and the job's warnings (array of text).
inline constexpr char kPoseReport[] = "PoseReportJSON";
inline constexpr char kPoseWarnings[] = "PoseWarnings";
}  // namespace segmentation

namespace cage {
inline constexpr char kClassName[] = "vtkMRMLReposeCageNode";
inline constexpr char kFile[] = "FileName";  // .vtk or .obj
inline constexpr char kTargetVertexCount[] = "TargetVertexCount";
inline constexpr char kDilationMm[] = "DilationMm";
// The setting the cage was built with, asked and tried (Core's CageLadder.h, CageChoice::json);
// written by Core's scene folders, absent from older scenes and from the workbench's.
inline constexpr char kChoice[] = "CageChoice";
inline constexpr char kHandleGroups[] = "HandleGroups";  // [{name, vertices}]
inline constexpr char kGroupName[] = "name";
inline constexpr char kGroupVertices[] = "vertices";
}  // namespace cage

namespace transfer_mesh {
inline constexpr char kClassName[] = "vtkMRMLReposeTransferMeshNode";
inline constexpr char kFile[] = "FileName";  // .vtu; its Green coordinates beside it (.green)
inline constexpr char kSizeMm[] = "SizeMm";
// A mesh refined for a pose (seed section 4.2): the vertices of the mesh it was refined from, and
// per round its vertices and maximum error e^G (arrays); absent for a mesh built whole.
inline constexpr char kRefinedFromVertices[] = "RefinedFromVertices";
inline constexpr char kRefinementVertices[] = "RefinementVertices";
inline constexpr char kRefinementMaxErrors[] = "RefinementMaxErrors";
}  // namespace transfer_mesh

namespace pose {
inline constexpr char kClassName[] = "vtkMRMLReposePoseNode";
inline constexpr char kFile[] = "FileName";  // .pose.json
inline constexpr char kCurrentFrame[] = "CurrentFrame";
}  // namespace pose

}  // namespace repose::scene_schema
