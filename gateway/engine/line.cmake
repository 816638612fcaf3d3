# The sans-I/O heart of a serial line: scheduler (which transaction next), line master
# (timing and framing of the one in flight), wire-time arithmetic. No I/O, no clock.
add_library(fb_engine_line STATIC
  ${CMAKE_CURRENT_LIST_DIR}/transaction.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_timing.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_stats.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_codec.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_master.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_scheduler.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_core.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_delivery.cpp
)
target_include_directories(fb_engine_line PUBLIC ${PROJECT_SOURCE_DIR}/gateway)
target_link_libraries(fb_engine_line PUBLIC fb_protocol PRIVATE fb_build_options)
