// vtkSlicerReposeLogic::Guarded, the one guarded call of the Logic's public methods that can
// fail (included by the Logic's .cxx files only).
#pragma once

#include "vtkSlicerReposeLogic.h"

#include <exception>
#include <new>

template <class Result, class Body>
Result vtkSlicerReposeLogic::Guarded(Result failed, Body&& body) {
  this->LastErrorMessage.clear();
  try {
    return body();
  } catch (const std::bad_alloc&) {
    this->LastErrorMessage = "not enough memory for this step";
  } catch (const std::exception& e) {
    this->LastErrorMessage = e.what();  // Core's errors are one line naming the file or field
  }
  return failed;
}
