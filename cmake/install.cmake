# cmake --install: the `pathex` command, its man page and bash completion, the static library
# with the API header <pathex/pathex.h>, and a CMake package (find_package(pathex) gives the
# imported target pathex::pathex). Test: tests/package (installs to a temporary prefix and builds
# examples/ against it).
include(CMakePackageConfigHelpers)

add_library(pathex::pathex ALIAS pathex_lib)

# The man page and the completion script are generated from the CLI definitions by the binary
# itself (`pathex --man`, `pathex --bash-completion`), so they cannot drift from --help.
foreach(kind IN ITEMS man bash-completion)
  set(out ${PROJECT_BINARY_DIR}/share/pathex.${kind})
  add_custom_command(OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:pathex> -DARG=--${kind} -DOUT=${out}
            -P ${PROJECT_SOURCE_DIR}/cmake/capture.cmake
    DEPENDS pathex ${PROJECT_SOURCE_DIR}/cmake/capture.cmake
    COMMENT "Generating pathex --${kind}" VERBATIM)
  list(APPEND pathex_generated_docs ${out})
endforeach()
add_custom_target(pathex_docs ALL DEPENDS ${pathex_generated_docs})

install(TARGETS pathex RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS pathex_image LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/pathex)  # src/io/image_file.h
install(TARGETS pathex_lib EXPORT pathexTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/pathex DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_BINARY_DIR}/share/pathex.man DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 RENAME pathex.1)
install(FILES ${PROJECT_BINARY_DIR}/share/pathex.bash-completion
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME pathex)

set(pathex_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/pathex)
install(EXPORT pathexTargets NAMESPACE pathex:: DESTINATION ${pathex_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/pathexConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pathexConfig.cmake INSTALL_DESTINATION ${pathex_cmake_dir}
  PATH_VARS CMAKE_INSTALL_BINDIR)
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pathexConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pathexConfig.cmake ${PROJECT_BINARY_DIR}/pathexConfigVersion.cmake
        DESTINATION ${pathex_cmake_dir})
