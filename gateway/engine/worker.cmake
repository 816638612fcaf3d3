# Line workers: the I/O driver of one serial line (asio readiness on the port's fd,
# one timer for the master's deadlines, reopen with back-off) over the sans-I/O
# scheduler and line master.
add_library(fb_engine_worker STATIC
  ${CMAKE_CURRENT_LIST_DIR}/line_worker_port.cpp
  ${CMAKE_CURRENT_LIST_DIR}/line_worker.cpp
)
target_include_directories(fb_engine_worker PUBLIC ${PROJECT_SOURCE_DIR}/gateway)
target_link_libraries(fb_engine_worker PUBLIC fb_engine_line fb_engine_io fb_asio
  PRIVATE fb_build_options)
