# The Debian package (tools/package.sh [amd64|arm64], the .deb in dist/): CPack's DEB generator over the install
# rules, configured with -DCMAKE_INSTALL_PREFIX=/usr -DMCSLAM_PACKAGE=ON. What it holds and how it behaves on
# install, upgrade and removal: docs/package.md.
option(MCSLAM_PACKAGE "Install what the Debian package adds: /etc/mcslamd/mcslamd.yaml, copyright, changelog" OFF)
set(CPACK_PACKAGE_CONTACT "mcslam developers <mcslam-dev@users.noreply.github.com>")
if(MCSLAM_PACKAGE)
  # The configuration as shipped is the simulated rig: started, the unit runs on any machine, and nothing it
  # publishes could pass for a real robot's pose, as the package neither enables nor starts it (docs/package.md).
  install(FILES ${PROJECT_SOURCE_DIR}/config/mcslamd-sim.yaml DESTINATION ${CMAKE_INSTALL_FULL_SYSCONFDIR}/mcslamd
          RENAME mcslamd.yaml)
  # Debian's documentation files: the copyright and, compressed, a changelog naming the version.
  install(FILES ${PROJECT_SOURCE_DIR}/systemd/debian/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})
  string(TIMESTAMP changelog_date "%a, %d %b %Y %H:%M:%S +0000" UTC)
  file(WRITE ${PROJECT_BINARY_DIR}/debian/changelog
       "mcslam (${PROJECT_VERSION}) unstable; urgency=medium\n\n  * Built from the project's sources; the history "
       "is the project's git log.\n\n -- ${CPACK_PACKAGE_CONTACT}  ${changelog_date}\n")
  install(CODE "execute_process(COMMAND gzip -9nf \"${PROJECT_BINARY_DIR}/debian/changelog\" -c
                                OUTPUT_FILE \"${PROJECT_BINARY_DIR}/debian/changelog.gz\")")
  install(FILES ${PROJECT_BINARY_DIR}/debian/changelog.gz DESTINATION ${CMAKE_INSTALL_DOCDIR})
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME mcslam)
set(CPACK_PACKAGE_VENDOR "mcslam")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "onboard fixed-memory visual SLAM for rigs of any number of cameras")
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "mcslamd runs multi-camera visual SLAM on a robot (GenICam cameras, a GPIO
trigger, or a simulated rig) and publishes the body pose over POSIX shared
memory and UDP, with place memory: relocalization, loop closure, saved maps.
.
Also: the tools (mcslam-run, mcslam-eval, mcslam-sim, mcslam-map, pose
consumers), the consumer's C++ headers with a CMake package config
(find_package(mcslam)) and the systemd unit.")
set(CPACK_PACKAGING_INSTALL_PREFIX ${CMAKE_INSTALL_PREFIX})
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
if(MCSLAM_DEB_ARCHITECTURE)
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${MCSLAM_DEB_ARCHITECTURE})
endif()
# The libraries the programs link directly, named as Debian 12 names them on every architecture (dpkg-shlibdeps
# would need the target's package database, which a cross build does not have).
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, \
libopencv-core406, libopencv-imgproc406, libopencv-imgcodecs406, libaravis-0.8-0, libgpiod2, libcholmod3, \
libsuitesparseconfig5, libspdlog1.10, libfmt9, libyaml-cpp0.7, libglib2.0-0, adduser")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3, aravis-tools")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/systemd/debian/conffiles ${PROJECT_SOURCE_DIR}/systemd/debian/postinst
    ${PROJECT_SOURCE_DIR}/systemd/debian/prerm ${PROJECT_SOURCE_DIR}/systemd/debian/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_STRIP_FILES ON)  # the binaries carry no debug information a user could use anyway (Release, no -g)
include(CPack)
