# ROS 1 bags without ROS (issue 32): Debian's rosbag_storage and the message headers
# (librosbag-storage-dev, lib{std,geometry,nav,sensor,tf2}-msgs-dev). Its rosbag_storage.pc
# requires a pluginlib.pc that Debian's pluginlib-dev (the ROS 2 one) does not ship, and bag.h
# includes <pluginlib/...> from below /usr/include/pluginlib, so the target is assembled here:
# rosbag_storage::rosbag_storage.
pkg_check_modules(ROSCPP_SERIALIZATION REQUIRED IMPORTED_TARGET roscpp_serialization rostime cpp_common)
find_library(ROSBAG_STORAGE_LIBRARY rosbag_storage REQUIRED)
find_path(ROSBAG_STORAGE_INCLUDE_DIR rosbag/bag.h REQUIRED)
find_path(PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib REQUIRED)
find_path(CLASS_LOADER_INCLUDE_DIR class_loader/multi_library_class_loader.hpp PATH_SUFFIXES class_loader REQUIRED)
find_path(RCUTILS_INCLUDE_DIR rcutils/logging_macros.h PATH_SUFFIXES rcutils REQUIRED)
find_path(RCPPUTILS_INCLUDE_DIR rcpputils/shared_library.hpp PATH_SUFFIXES rcpputils REQUIRED)
find_path(AMENT_INDEX_CPP_INCLUDE_DIR ament_index_cpp/get_package_prefix.hpp PATH_SUFFIXES ament_index_cpp REQUIRED)
find_path(TF2_MSGS_INCLUDE_DIR tf2_msgs/TFMessage.h REQUIRED)
add_library(rosbag_storage::rosbag_storage INTERFACE IMPORTED)
target_include_directories(rosbag_storage::rosbag_storage SYSTEM INTERFACE
  ${ROSBAG_STORAGE_INCLUDE_DIR} ${PLUGINLIB_INCLUDE_DIR} ${CLASS_LOADER_INCLUDE_DIR} ${RCUTILS_INCLUDE_DIR}
  ${RCPPUTILS_INCLUDE_DIR} ${AMENT_INDEX_CPP_INCLUDE_DIR} ${TF2_MSGS_INCLUDE_DIR})
target_link_libraries(rosbag_storage::rosbag_storage INTERFACE ${ROSBAG_STORAGE_LIBRARY} console_bridge
                      PkgConfig::ROSCPP_SERIALIZATION)
