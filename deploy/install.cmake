# Install rules of the files around the binaries (the binaries' own rules are beside
# their targets). Two components, one per Debian package (deploy/debian):
#   daemon     fieldbridge, its systemd units, sysusers.d entry, configuration, man pages, docs
#   simulator  fieldbridge-sim, its man page and doc
# `cmake --install build --component daemon` needs only the fieldbridge target built.

# systemd's directories. With the prefix /usr they are the system's own (systemd.pc:
# /lib/systemd/system on Debian 12, where dh_installsystemd looks for units); with any
# other prefix they are below it (systemd also reads /usr/local/lib/systemd/system).
set(_fb_unit_dir "${CMAKE_INSTALL_PREFIX}/lib/systemd/system")
set(_fb_sysusers_dir "${CMAKE_INSTALL_PREFIX}/lib/sysusers.d")
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  pkg_get_variable(_fb_pc_unit_dir systemd systemdsystemunitdir)
  pkg_get_variable(_fb_pc_sysusers_dir systemd sysusersdir)
  if(_fb_pc_unit_dir)
    set(_fb_unit_dir "${_fb_pc_unit_dir}")
  endif()
  if(_fb_pc_sysusers_dir)
    set(_fb_sysusers_dir "${_fb_pc_sysusers_dir}")
  endif()
endif()
set(FIELDBRIDGE_SYSTEMD_UNIT_DIR "${_fb_unit_dir}" CACHE PATH "Where the systemd units are installed")
set(FIELDBRIDGE_SYSUSERS_DIR "${_fb_sysusers_dir}" CACHE PATH "Where the sysusers.d entry is installed")

set(_fb_deploy "${PROJECT_SOURCE_DIR}/deploy")
set(_fb_config_dir "${CMAKE_INSTALL_FULL_SYSCONFDIR}/fieldbridge")

install(FILES "${_fb_deploy}/fieldbridge.service" DESTINATION "${FIELDBRIDGE_SYSTEMD_UNIT_DIR}"
        COMPONENT daemon)
# Socket activation of port 502 (docs/service.md, "Socket activation").
install(FILES "${_fb_deploy}/fieldbridge.socket" DESTINATION "${FIELDBRIDGE_SYSTEMD_UNIT_DIR}"
        COMPONENT daemon)
install(FILES "${_fb_deploy}/fieldbridge.sysusers" DESTINATION "${FIELDBRIDGE_SYSUSERS_DIR}"
        RENAME fieldbridge.conf COMPONENT daemon)

# The commented example becomes the configuration the unit reads. An existing file is
# an operator's configuration: it is kept (the Debian package has it as a conffile,
# which dpkg protects the same way).
install(CODE "
  set(_fb_conf \"\$ENV{DESTDIR}${_fb_config_dir}/fieldbridge.yaml\")
  if(EXISTS \"\${_fb_conf}\")
    message(STATUS \"Kept (not overwritten): \${_fb_conf}\")
  else()
    file(INSTALL DESTINATION \"${_fb_config_dir}\" TYPE FILE
         FILES \"${PROJECT_SOURCE_DIR}/config/fieldbridge.example.yaml\" RENAME fieldbridge.yaml)
  endif()
" COMPONENT daemon)

install(FILES "${_fb_deploy}/man/fieldbridge.8" DESTINATION "${CMAKE_INSTALL_MANDIR}/man8" COMPONENT daemon)
install(FILES "${_fb_deploy}/man/fieldbridge.yaml.5" DESTINATION "${CMAKE_INSTALL_MANDIR}/man5"
        COMPONENT daemon)
install(FILES README.md docs/architecture.md docs/configuration.md docs/modbus-tcp.md docs/mqtt.md
              docs/protocols.md docs/r6-passthrough.md docs/registers.md docs/service.md docs/devices.md
        DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/fieldbridge" COMPONENT daemon)
install(FILES config/fieldbridge.example.yaml DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/fieldbridge/examples"
        COMPONENT daemon)
# The shipped device definitions (docs/devices.md): the last of the default
# `definitions:` directories, after the site's /etc/fieldbridge/devices. The built-in
# types' files among them are also compiled into the binary (gateway/config/CMakeLists.txt).
install(DIRECTORY config/devices/ DESTINATION "${CMAKE_INSTALL_DATADIR}/fieldbridge/devices" COMPONENT daemon
        FILES_MATCHING PATTERN "*.yaml")

if(TARGET fieldbridge-sim)
  install(FILES "${_fb_deploy}/man/fieldbridge-sim.1" DESTINATION "${CMAKE_INSTALL_MANDIR}/man1"
          COMPONENT simulator)
  install(FILES docs/simulator.md DESTINATION "${CMAKE_INSTALL_DATADIR}/doc/fieldbridge-sim"
          COMPONENT simulator)
endif()
