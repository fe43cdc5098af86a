#include "vtkMRMLReposeScene.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"

#include "repose/schema/SceneSchema.h"

#include <vtkObjectFactory.h>

#include <set>

vtkStandardNewMacro(vtkMRMLReposeScene);

vtkSmartPointer<vtkMRMLReposeNode> vtkMRMLReposeScene::CreateNodeByClass(
    const std::string& className) {
  namespace sc = repose::scene_schema;
  if (className == sc::segmentation::kClassName)
    return vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New();
  if (className == sc::cage::kClassName) return vtkSmartPointer<vtkMRMLReposeCageNode>::New();
  if (className == sc::transfer_mesh::kClassName)
    return vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New();
  if (className == sc::pose::kClassName) return vtkSmartPointer<vtkMRMLReposePoseNode>::New();
  return nullptr;
}

std::string vtkMRMLReposeScene::AddNode(vtkMRMLReposeNode* node) {
  if (!node) return "";
  for (const auto& n : this->Nodes)
    if (n == node) return node->GetID();
  if (node->GetID().empty() || this->GetNodeByID(node->GetID())) {
    for (int k = 1;; ++k) {
      const std::string id = std::string(node->GetNodeClassName()) + std::to_string(k);
      if (!this->GetNodeByID(id)) {
        node->SetID(id);
        break;
      }
    }
  }
  this->Nodes.emplace_back(node);
  this->Modified();
  return node->GetID();
}

void vtkMRMLReposeScene::RemoveNode(vtkMRMLReposeNode* node) {
  for (auto it = this->Nodes.begin(); it != this->Nodes.end(); ++it)
    if (*it == node) {
      this->Nodes.erase(it);
      this->Modified();
      return;
    }
}

void vtkMRMLReposeScene::Clear() {
  if (this->Nodes.empty()) return;
  this->Nodes.clear();
  this->Modified();
}

vtkMRMLReposeNode* vtkMRMLReposeScene::GetNodeByID(const std::string& id) const {
  for (const auto& n : this->Nodes)
    if (n->GetID() == id) return n;
  return nullptr;
}

std::vector<vtkMRMLReposeNode*> vtkMRMLReposeScene::GetNodesByClass(
    const std::string& className) const {
  std::vector<vtkMRMLReposeNode*> out;
  for (const auto& n : this->Nodes)
    if (className == n->GetNodeClassName()) out.push_back(n);
  return out;
}

vtkMRMLReposeNode* vtkMRMLReposeScene::GetNthNode(int n) const {
  return n >= 0 && n < this->GetNumberOfNodes() ? this->Nodes[n].GetPointer() : nullptr;
}

vtkMRMLReposeNode* vtkMRMLReposeScene::GetReferencedNode(vtkMRMLReposeNode* node,
                                                         const std::string& role) const {
  return node ? this->GetNodeByID(node->GetNodeReferenceID(role)) : nullptr;
}

std::string vtkMRMLReposeScene::WriteJSON() const {
  nlohmann::ordered_json nodes = nlohmann::ordered_json::array();
  for (const auto& n : this->Nodes) nodes.push_back(n->ToJSON());
  namespace sc = repose::scene_schema;
  return nlohmann::ordered_json{
      {sc::kFormatKey, sc::kFormat}, {sc::kVersionKey, sc::kVersion}, {sc::kNodes, nodes}}
      .dump(2);
}

bool vtkMRMLReposeScene::ReadJSON(const std::string& text, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = "scene JSON: " + message;
    return false;
  };
  namespace sc = repose::scene_schema;
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) return fail("not valid JSON");
  if (!json.is_object() || json.value(sc::kFormatKey, "") != sc::kFormat)
    return fail(std::string(sc::kFormatKey) + ": expected \"" + sc::kFormat + "\"");
  if (json.value(sc::kVersionKey, 0) != sc::kVersion)
    return fail(std::string(sc::kVersionKey) + ": expected " + std::to_string(sc::kVersion));
  if (!json.contains(sc::kNodes) || !json[sc::kNodes].is_array())
    return fail(std::string(sc::kNodes) + ": expected an array");
  std::vector<vtkSmartPointer<vtkMRMLReposeNode>> nodes;
  std::set<std::string> ids;
  for (std::size_t i = 0; i < json[sc::kNodes].size(); ++i) {
    const nlohmann::json& j = json[sc::kNodes][i];
    const std::string f = "nodes[" + std::to_string(i) + "]";
    if (!j.is_object() || !j.contains(sc::kClass) || !j[sc::kClass].is_string())
      return fail(f + ".class: expected a node class name");
    auto node = CreateNodeByClass(j[sc::kClass].get<std::string>());
    if (!node) return fail(f + ".class: unknown node class " + j[sc::kClass].dump());
    if (!j.contains(sc::kId) || !j[sc::kId].is_string() || j[sc::kId].get<std::string>().empty())
      return fail(f + ".id: expected a node ID");
    if (!ids.insert(j[sc::kId].get<std::string>()).second)
      return fail(f + ".id: " + j[sc::kId].dump() + " used twice");
    std::string problem;
    if (!node->FromJSON(j, &problem)) return fail(f + ": " + problem);
    node->SetID(j[sc::kId].get<std::string>());
    nodes.push_back(node);
  }
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (const auto& [role, id] : nodes[i]->GetNodeReferences())
      if (!ids.count(id))
        return fail("nodes[" + std::to_string(i) + "].references." + role + ": no node " + id);
  this->Nodes = nodes;
  this->Modified();
  return true;
}

void vtkMRMLReposeScene::PrintSelf(ostream& os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  for (const auto& n : this->Nodes)
    os << indent << n->GetID() << " (" << n->GetNodeClassName() << ") " << n->GetName() << "\n";
}
