#include "vtkMRMLReposeNode.h"
#include "repose/schema/SceneSchema.h"

namespace sc = repose::scene_schema;

void vtkMRMLReposeNode::SetID(const std::string& id) {
  this->SetField(this->ID, id);
}
void vtkMRMLReposeNode::SetName(const std::string& name) {
  this->SetField(this->Name, name);
}

void vtkMRMLReposeNode::SetNodeReferenceID(const std::string& role, const std::string& id) {
  const auto it = this->References.find(role);
  if (id.empty()) {
    if (it == this->References.end()) return;
    this->References.erase(it);
  } else {
    if (it != this->References.end() && it->second == id) return;
    this->References[role] = id;
  }
  this->Modified();
}

std::string vtkMRMLReposeNode::GetNodeReferenceID(const std::string& role) const {
  const auto it = this->References.find(role);
  return it == this->References.end() ? std::string() : it->second;
}

nlohmann::ordered_json vtkMRMLReposeNode::ToJSON() const {
  nlohmann::ordered_json json = {{sc::kClass, this->GetNodeClassName()},
                                 {sc::kId, this->ID},
                                 {sc::kName, this->Name},
                                 {sc::kReferences, this->References}};
  this->WriteFields(json);
  return json;
}

std::string vtkMRMLReposeNode::WriteJSON() const {
  return this->ToJSON().dump(2);
}

bool vtkMRMLReposeNode::ReadJSON(const std::string& text, std::string* error) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded()) {
    if (error) *error = std::string(this->GetNodeClassName()) + " JSON: not valid JSON";
    return false;
  }
  return this->FromJSON(json, error);
}

bool vtkMRMLReposeNode::FromJSON(const nlohmann::json& json, std::string* error) {
  std::string problem;
  auto fail = [&](const std::string& message) {
    if (error) *error = std::string(this->GetNodeClassName()) + " JSON: " + message;
    return false;
  };
  if (!json.is_object()) return fail("expected an object");
  if (json.contains(sc::kClass) && json[sc::kClass] != this->GetNodeClassName())
    return fail("class is " + json[sc::kClass].dump() + ", not " + this->GetNodeClassName());
  if (json.contains(sc::kId) && !json[sc::kId].is_string()) return fail("id: expected a string");
  if (!CheckString(json, sc::kName, problem)) return fail(problem);
  if (json.contains(sc::kReferences)) {
    if (!json[sc::kReferences].is_object()) return fail("references: expected an object");
    for (const auto& [role, id] : json[sc::kReferences].items())
      if (!id.is_string()) return fail("references." + role + ": expected a node ID");
  }
  if (!this->ReadFields(json, false, problem)) return fail(problem);
  const int state = this->StartModify();
  if (json.contains(sc::kName)) this->SetName(json[sc::kName].get<std::string>());
  if (json.contains(sc::kReferences)) {
    std::map<std::string, std::string> refs;
    for (const auto& [role, id] : json[sc::kReferences].items()) refs[role] = id.get<std::string>();
    if (refs != this->References) {
      this->References = refs;
      this->Modified();
    }
  }
  this->ReadFields(json, true, problem);
  this->EndModify(state);
  return true;
}

void vtkMRMLReposeNode::Copy(vtkMRMLReposeNode* other) {
  if (!other || other == this || std::string(other->GetNodeClassName()) != GetNodeClassName())
    return;
  const int state = this->StartModify();
  this->SetName(other->Name);
  if (this->References != other->References) {
    this->References = other->References;
    this->Modified();
  }
  this->CopyContent(other);
  this->EndModify(state);
}

int vtkMRMLReposeNode::StartModify() {
  return this->DisableModified++;
}
void vtkMRMLReposeNode::EndModify(int previousDisableState) {
  this->DisableModified = previousDisableState;
  if (this->DisableModified == 0 && this->ModifiedWhileDisabled) {
    this->ModifiedWhileDisabled = false;
    this->Modified();
  }
}
void vtkMRMLReposeNode::Modified() {
  if (this->DisableModified > 0) {
    this->ModifiedWhileDisabled = true;
    return;
  }
  this->Superclass::Modified();
}

void vtkMRMLReposeNode::PrintSelf(ostream& os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  const nlohmann::ordered_json json = this->ToJSON();  // kept alive for the loop
  for (const auto& [key, value] : json.items()) os << indent << key << ": " << value.dump() << "\n";
}

bool vtkMRMLReposeNode::CheckString(const nlohmann::json& json, const char* key,
                                    std::string& error) {
  if (!json.contains(key) || json[key].is_string()) return true;
  error = std::string(key) + ": expected a string";
  return false;
}
bool vtkMRMLReposeNode::CheckNumber(const nlohmann::json& json, const char* key,
                                    std::string& error) {
  if (!json.contains(key) || json[key].is_number()) return true;
  error = std::string(key) + ": expected a number";
  return false;
}
bool vtkMRMLReposeNode::CheckInteger(const nlohmann::json& json, const char* key,
                                     std::string& error) {
  if (!json.contains(key) || json[key].is_number_integer()) return true;
  error = std::string(key) + ": expected an integer";
  return false;
}
