# The engine of one configuration: config -> line workers and device agents.
add_library(fb_engine_assembly STATIC
  ${CMAKE_CURRENT_LIST_DIR}/engine_settings.cpp
  ${CMAKE_CURRENT_LIST_DIR}/engine.cpp
)
target_include_directories(fb_engine_assembly PUBLIC ${PROJECT_SOURCE_DIR}/gateway)
target_link_libraries(fb_engine_assembly
  PUBLIC fb_engine_worker fb_engine_agent fb_config fmt::fmt
  PRIVATE fb_build_options)
