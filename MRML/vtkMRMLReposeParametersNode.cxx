// vtkMRMLReposeParametersNode: field list, clamping setters, JSON and print. Every serialising
// function walks ForEachField, the one place that names the fields.
#include "vtkMRMLReposeParametersNode.h"

#include <vtkObjectFactory.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <limits>
#include <type_traits>

vtkStandardNewMacro(vtkMRMLReposeParametersNode);

template <class F>
void vtkMRMLReposeParametersNode::ForEachField(F&& f) {
  using Self = vtkMRMLReposeParametersNode;
  f("InputSegmentationNodeID", &Self::InputSegmentationNodeID, &Self::SetInputSegmentationNodeID);
  f("InputSegmentationPath", &Self::InputSegmentationPath, &Self::SetInputSegmentationPath);
  f("BodyPartMapPath", &Self::BodyPartMapPath, &Self::SetBodyPartMapPath);
  f("ImagePath", &Self::ImagePath, &Self::SetImagePath);
  f("CageVertexCount", &Self::CageVertexCount, &Self::SetCageVertexCount);
  f("CageDilationMm", &Self::CageDilationMm, &Self::SetCageDilationMm);
  f("TransferMeshSizeMm", &Self::TransferMeshSizeMm, &Self::SetTransferMeshSizeMm);
  f("OutputMemoryBudgetMB", &Self::OutputMemoryBudgetMB, &Self::SetOutputMemoryBudgetMB);
  f("OutputFolder", &Self::OutputFolder, &Self::SetOutputFolder);
  f("PosePath", &Self::PosePath, &Self::SetPosePath);
  f("ActivePoseNodeID", &Self::ActivePoseNodeID, &Self::SetActivePoseNodeID);
  f("ActiveGroup", &Self::ActiveGroup, &Self::SetActiveGroup);
  f("SelectedCageVertices", &Self::SelectedCageVertices, &Self::SetSelectedCageVertices);
  f("SelectedBodyPart", &Self::SelectedBodyPart, &Self::SetSelectedBodyPart);
  f("LabelOpacity", &Self::LabelOpacity, &Self::SetLabelOpacity);
  f("ShowBodyParts", &Self::ShowBodyParts, &Self::SetShowBodyParts);
  f("ShowJoints", &Self::ShowJoints, &Self::SetShowJoints);
  f("TissueTablePath", &Self::TissueTablePath, &Self::SetTissueTablePath);
  f("RigSummary", &Self::RigSummary, &Self::SetRigSummary);
  f("OutputSegmentationNodeID", &Self::OutputSegmentationNodeID,
    &Self::SetOutputSegmentationNodeID);
}

namespace {
// Sets a numeric member to `value` clamped to [lo, hi]; reports whether it changed.
// Non-finite values are refused so a NaN can never make every later set look like a change.
template <class T>
bool clampAssign(T& member, T value, T lo, T hi) {
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) return false;
  }
  const T clamped = std::clamp(value, lo, hi);
  if (member == clamped) return false;
  member = clamped;
  return true;
}

// A JSON integer as int, saturating, so 1e12 clamps to the top of a range instead of wrapping.
int saturatedInt(const nlohmann::json& v) {
  constexpr long long lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
  if (v.is_number_unsigned())
    return static_cast<int>(std::min<unsigned long long>(v.get<unsigned long long>(), hi));
  return static_cast<int>(std::clamp<long long>(v.get<long long>(), lo, hi));
}
}  // namespace

void vtkMRMLReposeParametersNode::SetCageVertexCount(int count) {
  if (clampAssign(this->CageVertexCount, count, CageVertexCountMin, CageVertexCountMax))
    this->Modified();
}
void vtkMRMLReposeParametersNode::SetCageDilationMm(double mm) {
  if (clampAssign(this->CageDilationMm, mm, 0.0, 1000.0)) this->Modified();
}
void vtkMRMLReposeParametersNode::SetTransferMeshSizeMm(double mm) {
  if (clampAssign(this->TransferMeshSizeMm, mm, 0.0, 1000.0)) this->Modified();
}
void vtkMRMLReposeParametersNode::SetOutputMemoryBudgetMB(int mib) {
  // 0 (or less): automatic, half the physical memory; else at least 64 MiB.
  if (clampAssign(this->OutputMemoryBudgetMB, mib <= 0 ? 0 : std::max(mib, 64), 0, 1 << 20))
    this->Modified();
}

void vtkMRMLReposeParametersNode::SetSelectedCageVertices(const std::vector<int>& vertices) {
  std::vector<int> v;
  std::copy_if(vertices.begin(), vertices.end(), std::back_inserter(v),
               [](int i) { return i >= 0; });
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  if (v == this->SelectedCageVertices) return;
  this->SelectedCageVertices = std::move(v);
  this->Modified();
}

void vtkMRMLReposeParametersNode::SetSelectedBodyPart(int label) {
  if (clampAssign(this->SelectedBodyPart, label, 0, std::numeric_limits<int>::max()))
    this->Modified();
}

void vtkMRMLReposeParametersNode::SetLabelOpacity(double opacity) {
  if (clampAssign(this->LabelOpacity, opacity, 0.0, 1.0)) this->Modified();
}

void vtkMRMLReposeParametersNode::SetShowBodyParts(bool show) {
  if (this->ShowBodyParts == show) return;
  this->ShowBodyParts = show;
  this->Modified();
}

void vtkMRMLReposeParametersNode::SetShowJoints(bool show) {
  if (this->ShowJoints == show) return;
  this->ShowJoints = show;
  this->Modified();
}

int vtkMRMLReposeParametersNode::StartModify() {
  return this->DisableModified++;
}
void vtkMRMLReposeParametersNode::EndModify(int previousDisableState) {
  this->DisableModified = previousDisableState;
  if (this->DisableModified == 0 && this->ModifiedWhileDisabled) {
    this->ModifiedWhileDisabled = false;
    this->Modified();
  }
}
void vtkMRMLReposeParametersNode::Modified() {
  if (this->DisableModified > 0) {
    this->ModifiedWhileDisabled = true;
    return;
  }
  this->Superclass::Modified();
}

void vtkMRMLReposeParametersNode::Copy(vtkMRMLReposeParametersNode* other) {
  if (!other || other == this) return;
  const int state = this->StartModify();
  ForEachField([&](const char*, auto member, auto setter) { (this->*setter)(other->*member); });
  this->EndModify(state);
}

std::string vtkMRMLReposeParametersNode::WriteJSON() const {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  ForEachField([&](const char* name, auto member, auto) { json[name] = this->*member; });
  return json.dump(2);
}

bool vtkMRMLReposeParametersNode::ReadJSON(const std::string& text, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = "parameters JSON: " + message;
    return false;
  };
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded()) return fail("not valid JSON");
  if (!json.is_object()) return fail("expected an object");
  // Validate everything first so a bad file leaves the node untouched.
  for (const auto& item : json.items()) {
    bool known = false, typeOk = false;
    ForEachField([&](const char* name, auto member, auto) {
      if (item.key() != name) return;
      known = true;
      using T = std::decay_t<decltype(this->*member)>;
      const auto& v = item.value();
      if constexpr (std::is_same_v<T, std::string>)
        typeOk = v.is_string();
      else if constexpr (std::is_same_v<T, std::vector<int>>)
        typeOk = v.is_array() && std::all_of(v.begin(), v.end(), [](const nlohmann::json& e) {
                   return e.is_number_integer();
                 });
      else if constexpr (std::is_same_v<T, bool>)
        typeOk = v.is_boolean();
      else if constexpr (std::is_integral_v<T>)
        typeOk = v.is_number_integer();
      else
        typeOk = v.is_number();
    });
    if (!known) return fail("unknown key '" + item.key() + "'");
    if (!typeOk) return fail("wrong type for '" + item.key() + "'");
  }
  const int state = this->StartModify();
  ForEachField([&](const char* name, auto member, auto setter) {
    using T = std::decay_t<decltype(this->*member)>;
    const auto it = json.find(name);
    if (it == json.end()) return;
    if constexpr (std::is_same_v<T, bool>)
      (this->*setter)(it->template get<bool>());
    else if constexpr (std::is_integral_v<T>)
      (this->*setter)(saturatedInt(*it));
    else if constexpr (std::is_same_v<T, std::vector<int>>) {
      std::vector<int> v;
      for (const auto& e : *it) v.push_back(saturatedInt(e));
      (this->*setter)(v);
    } else
      (this->*setter)(it->template get<T>());
  });
  this->EndModify(state);
  return true;
}

void vtkMRMLReposeParametersNode::PrintSelf(ostream& os, vtkIndent indent) {
  this->Superclass::PrintSelf(os, indent);
  ForEachField([&](const char* name, auto member, auto) {
    using T = std::decay_t<decltype(this->*member)>;
    os << indent << name << ":";
    if constexpr (std::is_same_v<T, std::vector<int>>) {
      for (int v : this->*member) os << " " << v;
    } else {
      os << " " << this->*member;
    }
    os << "\n";
  });
}
