// What the module's logic and its three parts (jobs, live posing, pose edits) share: the scene,
// the parameter node that holds the module's state, the one worker every long step runs on, and
// the last error message. Owned by vtkSlicerReposeLogic; included by the Logic's .cxx files only.
#pragma once

#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkSlicerReposeJob.h"

#include <vtkSmartPointer.h>

#include <exception>
#include <memory>
#include <new>
#include <string>

class vtkSlicerReposeLiveLogic;

struct vtkSlicerReposeLogicContext {
  vtkSmartPointer<vtkMRMLReposeScene> Scene = vtkSmartPointer<vtkMRMLReposeScene>::New();
  vtkSmartPointer<vtkMRMLReposeParametersNode> ParameterNode;
  std::unique_ptr<vtkSlicerReposeJob> Job = std::make_unique<vtkSlicerReposeJob>();
  std::string LastErrorMessage;
  // The live part, which the jobs (a refinement adapts to its frame) and the pose edits (a group
  // from the live cage; a joint stops live posing) consult. Owned by the module's logic; null
  // once it is gone.
  vtkSlicerReposeLiveLogic* Live = nullptr;

  std::string TissueTablePath() const {
    return this->ParameterNode ? this->ParameterNode->GetTissueTablePath() : std::string();
  }
  // The one guarded call behind every public method that can fail: the message cleared, an
  // exception becomes its one line (Core's errors name the file or field) and the failed result.
  template <class Result, class Body>
  Result Guarded(Result failed, Body&& body) {
    this->LastErrorMessage.clear();
    try {
      return body();
    } catch (const std::bad_alloc&) {
      this->LastErrorMessage = "not enough memory for this step";
    } catch (const std::exception& e) {
      this->LastErrorMessage = e.what();
    }
    return failed;
  }
};
