// vtkMRMLReposeNode: what every Repose data node shares, shaped as Slicer's vtkMRMLNode: an ID
// given by the scene, a name, references to other nodes by role and ID, Modified events batched
// by StartModify/EndModify, and one JSON form. Write, read, copy and print all go through the
// subclass's field list (WriteFields/ReadFields), so they list the same fields. Bulk data (VTK
// data objects) is not in the JSON: the node names its file, the Logic reads and writes it.
#pragma once

#include "vtkSlicerReposeModuleMRMLExport.h"

#include <vtkObject.h>

#include <nlohmann/json.hpp>

#include <map>
#include <string>

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposeNode : public vtkObject {
 public:
  vtkTypeMacro(vtkMRMLReposeNode, vtkObject);
  // One line per JSON field ("key: value"), after the VTK object header.
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // The class name the scene file uses to recreate the node, e.g. "vtkMRMLReposeCageNode".
  virtual const char* GetNodeClassName() const = 0;

  const std::string& GetID() const { return this->ID; }
  void SetID(const std::string& id);  // the scene does this
  const std::string& GetName() const { return this->Name; }
  void SetName(const std::string& name);

  // References to other nodes by role (e.g. "segmentation" -> "vtkMRMLReposeSegmentationNode1").
  // An empty ID removes the reference.
  void SetNodeReferenceID(const std::string& role, const std::string& id);
  std::string GetNodeReferenceID(const std::string& role) const;
  const std::map<std::string, std::string>& GetNodeReferences() const { return this->References; }

  // {"class", "id", "name", "references", then the node's own fields}.
  std::string WriteJSON() const;
  nlohmann::ordered_json ToJSON() const;
  // Sets the name, references and fields present; the class must match and the ID is kept. On a
  // parse or type error returns false, fills `error` naming the field, and changes nothing.
  bool ReadJSON(const std::string& json, std::string* error = nullptr);
  bool FromJSON(const nlohmann::json& json, std::string* error = nullptr);

  // Name, references, fields and bulk data (deep copies); not the ID. One ModifiedEvent at most.
  void Copy(vtkMRMLReposeNode* other);

  // Between StartModify and EndModify, ModifiedEvent is held back and fired once if anything
  // changed. Nests.
  int StartModify();
  void EndModify(int previousDisableState);
  void Modified() override;

 protected:
  vtkMRMLReposeNode() = default;
  ~vtkMRMLReposeNode() override = default;

  virtual void WriteFields(nlohmann::ordered_json& json) const = 0;
  // Checks the fields present in `json` when `apply` is false (returning false with `error` on
  // the first bad one), sets them when it is true (only called after a successful check).
  virtual bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) = 0;
  // The subclass's fields and bulk data from `other` (same class).
  virtual void CopyContent(vtkMRMLReposeNode* other) = 0;

  // Helpers for ReadFields: type checks that name the field.
  static bool CheckString(const nlohmann::json& json, const char* key, std::string& error);
  static bool CheckNumber(const nlohmann::json& json, const char* key, std::string& error);
  static bool CheckInteger(const nlohmann::json& json, const char* key, std::string& error);

  // Assigns and calls Modified only on change.
  template <class T>
  void SetField(T& member, const T& value) {
    if (member == value) return;
    member = value;
    this->Modified();
  }

 private:
  vtkMRMLReposeNode(const vtkMRMLReposeNode&) = delete;
  void operator=(const vtkMRMLReposeNode&) = delete;

  std::string ID, Name;
  std::map<std::string, std::string> References;
  int DisableModified = 0;
  bool ModifiedWhileDisabled = false;
};
