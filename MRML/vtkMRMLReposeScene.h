// vtkMRMLReposeScene: the nodes of one posing session, by ID, and their JSON form (the scene.json
// of a scene folder, docs/FORMATS.md). Slicer's vtkMRMLScene reduced to what the module needs:
// add (the scene gives IDs), find by ID or class, remove, references checked on load. The data
// files the nodes name are read and written by the Logic.
#pragma once

#include "vtkMRMLReposeNode.h"

#include <vtkObject.h>
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposeScene : public vtkObject {
 public:
  static vtkMRMLReposeScene* New();
  vtkTypeMacro(vtkMRMLReposeScene, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // Gives the node a fresh ID (class name + number) unless it has one not yet used; returns it.
  std::string AddNode(vtkMRMLReposeNode* node);
  void RemoveNode(vtkMRMLReposeNode* node);
  void Clear();
  vtkMRMLReposeNode* GetNodeByID(const std::string& id) const;
  std::vector<vtkMRMLReposeNode*> GetNodesByClass(const std::string& className) const;
  int GetNumberOfNodes() const { return static_cast<int>(this->Nodes.size()); }
  vtkMRMLReposeNode* GetNthNode(int n) const;
  // The node `node` refers to under `role`, or null.
  vtkMRMLReposeNode* GetReferencedNode(vtkMRMLReposeNode* node, const std::string& role) const;

  // {"format": "repose-scene", "version": 2, "nodes": [node JSON...]}.
  std::string WriteJSON() const;
  // Replaces the scene's nodes with those of `json` (created by class name). On an unknown
  // class, a bad node, a duplicate ID or a reference to a missing node, returns false with
  // `error` naming it and leaves the scene as it was.
  bool ReadJSON(const std::string& json, std::string* error = nullptr);

  // A new node of a Repose class by name, or null.
  static vtkSmartPointer<vtkMRMLReposeNode> CreateNodeByClass(const std::string& className);

 protected:
  vtkMRMLReposeScene() = default;
  ~vtkMRMLReposeScene() override = default;

 private:
  vtkMRMLReposeScene(const vtkMRMLReposeScene&) = delete;
  void operator=(const vtkMRMLReposeScene&) = delete;
  std::vector<vtkSmartPointer<vtkMRMLReposeNode>> Nodes;
};
