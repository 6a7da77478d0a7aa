# Included into each pip_ros package's project() (CMAKE_PROJECT_INCLUDE, set by
# build_into_venv.py): generate only what rclpy uses on the pip ROS, the C structs, the type
# descriptions, the C type support and its Fast DDS (rmw_fastrtps_cpp) implementation, and the
# Python bindings. The C++ headers and type supports and the C introspection type support
# (compiled C++ for every message, most of a build's time) are not generated.
set(STATIC_ROSIDL_TYPESUPPORT_C rosidl_typesupport_fastrtps_c)
find_package(rosidl_default_generators REQUIRED)
list(FILTER AMENT_EXTENSIONS_rosidl_generate_idl_interfaces EXCLUDE REGEX
  "^(rosidl_generator_cpp|rosidl_typesupport_cpp|rosidl_typesupport_fastrtps_cpp|rosidl_typesupport_introspection_cpp|rosidl_typesupport_introspection_c):")
message(STATUS "pip_ros: interface generators: ${AMENT_EXTENSIONS_rosidl_generate_idl_interfaces}")
