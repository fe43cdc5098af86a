# qSlicerReposeModule: the loadable module plugin, built into build/lib/repose-modules/Repose/
# beside a copy of module.json, which is where the workbench looks for modules.

# module.json is the module's description for the host; its version must be the project's and
# its library this target, or discovery would reject the plugin. Checked at configure time.
set(REPOSE_MODULE_JSON_FILE ${PROJECT_SOURCE_DIR}/module.json)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${REPOSE_MODULE_JSON_FILE})
file(READ ${REPOSE_MODULE_JSON_FILE} REPOSE_MODULE_JSON)
string(JSON REPOSE_MODULE_NAME GET "${REPOSE_MODULE_JSON}" name)
string(JSON REPOSE_MODULE_VERSION GET "${REPOSE_MODULE_JSON}" version)
string(JSON REPOSE_MODULE_LIBRARY GET "${REPOSE_MODULE_JSON}" library)
if(NOT REPOSE_MODULE_VERSION STREQUAL PROJECT_VERSION)
  message(FATAL_ERROR "module.json version ${REPOSE_MODULE_VERSION} differs from project(VERSION "
                      "${PROJECT_VERSION}); keep them in sync")
endif()
if(NOT REPOSE_MODULE_LIBRARY STREQUAL "qSlicerReposeModule")
  message(FATAL_ERROR "module.json library '${REPOSE_MODULE_LIBRARY}' must be qSlicerReposeModule")
endif()

set(REPOSE_MODULE_OUTPUT_DIR ${CMAKE_BINARY_DIR}/lib/repose-modules/${REPOSE_MODULE_NAME})
add_library(qSlicerReposeModule MODULE
  ${PROJECT_SOURCE_DIR}/qSlicerReposeModule.h
  ${PROJECT_SOURCE_DIR}/qSlicerReposeModule.cxx
  ${PROJECT_SOURCE_DIR}/Resources/qSlicerReposeModule.qrc)
set_target_properties(qSlicerReposeModule PROPERTIES
  AUTOMOC ON
  AUTORCC ON
  LIBRARY_OUTPUT_DIRECTORY ${REPOSE_MODULE_OUTPUT_DIR})
target_link_libraries(qSlicerReposeModule PRIVATE qSlicerReposeModuleWidgets qReposeModuleInterface)
target_compile_options(qSlicerReposeModule PRIVATE ${REPOSE_WARNINGS})
configure_file(${REPOSE_MODULE_JSON_FILE} ${REPOSE_MODULE_OUTPUT_DIR}/module.json COPYONLY)
