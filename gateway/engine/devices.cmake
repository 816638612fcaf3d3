# Register image, point codec (points/) and device profiles (XEG, EXCD203MB, WTEC RTU, WTEC ASCII view,
# generic Modbus). Pure logic over the protocol codecs and the built-in types' definitions: no I/O, no clock.
add_library(fb_engine_devices STATIC
  ${CMAKE_CURRENT_LIST_DIR}/register_image.cpp
  ${CMAKE_CURRENT_LIST_DIR}/points/point_codec.cpp
  ${CMAKE_CURRENT_LIST_DIR}/points/point_requests.cpp
  ${CMAKE_CURRENT_LIST_DIR}/points/point_alarms.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/device_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/operations.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/field_setters.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/poll_plan.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/register_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/modbus_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/builtin_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/point_state.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/xeg_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/excd_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/wtec_common.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/wtec_rtu_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/wtec_ascii_image.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/wtec_ascii_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/generic_map.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/generic_profile.cpp
  ${CMAKE_CURRENT_LIST_DIR}/profiles/profile_factory.cpp
)
target_include_directories(fb_engine_devices PUBLIC ${PROJECT_SOURCE_DIR}/gateway)
# fb_config: the built-in types' compiled-in definitions (config/builtin_definitions.hpp).
target_link_libraries(fb_engine_devices PUBLIC fb_protocol fb_config PRIVATE fb_build_options)
