# Device agents: one device's profile, register image and poll schedule, and the
# translation of northbound requests into line transactions. Timers only, no I/O.
add_library(fb_engine_agent STATIC
  ${CMAKE_CURRENT_LIST_DIR}/poll_schedule.cpp
  ${CMAKE_CURRENT_LIST_DIR}/device_agent_answers.cpp
  ${CMAKE_CURRENT_LIST_DIR}/device_agent.cpp
  ${CMAKE_CURRENT_LIST_DIR}/device_agent_polls.cpp
  ${CMAKE_CURRENT_LIST_DIR}/device_agent_requests.cpp
)
target_include_directories(fb_engine_agent PUBLIC ${PROJECT_SOURCE_DIR}/gateway)
target_link_libraries(fb_engine_agent PUBLIC fb_engine_devices fb_engine_line fb_asio PRIVATE fb_build_options)
