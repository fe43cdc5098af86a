#include "vtkMRMLReposeScene.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"

#include <vtkObjectFactory.h>

#include <set>

vtkStandardNewMacro(vtkMRMLReposeScene);

vtkSmartPointer<vtkMRMLReposeNode> vtkMRMLReposeScene::CreateNodeByClass(
    const std::string& className) {
  if (className == "vtkMRMLReposeSegmentationNode")
    return vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New();
  if (className == "vtkMRMLReposeCageNode") return vtkSmartPointer<vtkMRMLReposeCageNode>::New();
  if (className == "vtkMRMLReposeTransferMeshNode")
    return vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New();
  if (className == "vtkMRMLReposePoseNode") return vtkSmartPointer<vtkMRMLReposePoseNode>::New();
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
  return nlohmann::ordered_json{{"format", "repose-scene"}, {"version", 2}, {"nodes", nodes}}.dump(
      2);
}

bool vtkMRMLReposeScene::ReadJSON(const std::string& text, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = "scene JSON: " + message;
    return false;
  };
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) return fail("not valid JSON");
  if (!json.is_object() || json.value("format", "") != "repose-scene")
    return fail("format: expected \"repose-scene\"");
  if (json.value("version", 0) != 2) return fail("version: expected 2");
  if (!json.contains("nodes") || !json["nodes"].is_array()) return fail("nodes: expected an array");
  std::vector<vtkSmartPointer<vtkMRMLReposeNode>> nodes;
  std::set<std::string> ids;
  for (std::size_t i = 0; i < json["nodes"].size(); ++i) {
    const nlohmann::json& j = json["nodes"][i];
    const std::string f = "nodes[" + std::to_string(i) + "]";
    if (!j.is_object() || !j.contains("class") || !j["class"].is_string())
      return fail(f + ".class: expected a node class name");
    auto node = CreateNodeByClass(j["class"].get<std::string>());
    if (!node) return fail(f + ".class: unknown node class " + j["class"].dump());
    if (!j.contains("id") || !j["id"].is_string() || j["id"].get<std::string>().empty())
      return fail(f + ".id: expected a node ID");
    if (!ids.insert(j["id"].get<std::string>()).second)
      return fail(f + ".id: " + j["id"].dump() + " used twice");
    std::string problem;
    if (!node->FromJSON(j, &problem)) return fail(f + ": " + problem);
    node->SetID(j["id"].get<std::string>());
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
