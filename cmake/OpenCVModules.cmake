# OpenCV's CMake package file ships only in Debian's libopencv-dev meta package, which drags in
# VTK, MPI and the contrib modules. The project needs a few modules, installed as their own
# -dev packages; this makes imported targets opencv_<module> for them.
find_path(OpenCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
foreach(module IN LISTS TRIMBOT_OPENCV_MODULES)
  find_library(OpenCV_${module}_LIBRARY NAMES opencv_${module} REQUIRED)
  add_library(opencv_${module} SHARED IMPORTED)
  set_target_properties(opencv_${module} PROPERTIES
    IMPORTED_LOCATION "${OpenCV_${module}_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${OpenCV_INCLUDE_DIR}")
  if(NOT module STREQUAL "core")
    set_property(TARGET opencv_${module} PROPERTY INTERFACE_LINK_LIBRARIES opencv_core)
  endif()
endforeach()
