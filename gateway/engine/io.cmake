# Line I/O: the serial port seam, its POSIX implementation (libmodbus set-up) and the
# TCP stream to a serial device server.
add_library(fb_engine_io STATIC
  ${CMAKE_CURRENT_LIST_DIR}/posix_serial_port.cpp
  ${CMAKE_CURRENT_LIST_DIR}/serial_low_latency.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tcp_stream_port.cpp
)
target_include_directories(fb_engine_io PUBLIC ${PROJECT_SOURCE_DIR}/gateway)
target_link_libraries(fb_engine_io PUBLIC fb_protocol PkgConfig::MODBUS PRIVATE fb_build_options)
