# Included into each pip_ros package's project() (CMAKE_PROJECT_INCLUDE, set by
# build_into_venv.py): generate only what rclpy uses on the pip ROS, the C structs, the type
# descriptions, the C type supports (Fast DDS's, and the introspection one, from which
# rmw_fastrtps builds the DDS type object) and the Python bindings. The C++ headers and type
# supports (compiled C++ for every message, most of a build's time) are not generated.
find_package(rosidl_default_generators REQUIRED)
list(FILTER AMENT_EXTENSIONS_rosidl_generate_idl_interfaces EXCLUDE REGEX
  "^(rosidl_generator_cpp|rosidl_typesupport_cpp|rosidl_typesupport_fastrtps_cpp|rosidl_typesupport_introspection_cpp):")
message(STATUS "pip_ros: interface generators: ${AMENT_EXTENSIONS_rosidl_generate_idl_interfaces}")
