# Shaders are validated at build time by glslangValidator, so a GLSL error fails the build, not a run,
# and are copied next to the executables (build tree) and installed beside them (share/tetrasand/shaders).
#
# tetrasand_add_shaders(<target> <file>...) with files relative to ${PROJECT_SOURCE_DIR}/shaders.
function(tetrasand_add_shaders target)
  set(stamps)
  set(shader_root ${PROJECT_SOURCE_DIR}/shaders)
  # A kernel may include any header of any stage (common/, preview/...), so each check depends on all.
  file(GLOB_RECURSE shared_headers CONFIGURE_DEPENDS ${shader_root}/*.h ${shader_root}/*.glsl)
  foreach(rel IN LISTS ARGN)
    set(src ${shader_root}/${rel})
    set(dst ${TETRASAND_SHADER_BUILD_DIR}/${rel})
    set(stamp ${CMAKE_CURRENT_BINARY_DIR}/shader-stamps/${rel}.ok)
    get_filename_component(stamp_dir ${stamp} DIRECTORY)
    get_filename_component(dst_dir ${dst} DIRECTORY)
    add_custom_command(
      OUTPUT ${stamp} ${dst}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${stamp_dir} ${dst_dir}
      # -G (GL SPIR-V) is the mode in which Debian's glslang 12 resolves #include; auto-mapping keeps
      # plain GL uniforms legal there. The output is discarded: drivers compile the GLSL at run time.
      COMMAND ${GLSLANG_VALIDATOR} --quiet -G --auto-map-locations --auto-map-bindings -o /dev/null -I${shader_root} -I${NANOVDB_INCLUDE_DIR} ${src}
      COMMAND ${CMAKE_COMMAND} -E copy_if_different ${src} ${dst}
      COMMAND ${CMAKE_COMMAND} -E touch ${stamp}
      DEPENDS ${src} ${shared_headers}
      COMMENT "glslangValidator ${rel}"
      VERBATIM)
    list(APPEND stamps ${stamp})
    get_filename_component(rel_dir ${rel} DIRECTORY)
    install(FILES ${src} DESTINATION share/tetrasand/shaders/${rel_dir})
  endforeach()
  add_custom_target(${target} ALL DEPENDS ${stamps})
endfunction()

# Header-only files shared by shaders (and, for layouts, by C++): copied, not validated alone.
function(tetrasand_add_shader_headers target)
  set(outs)
  foreach(rel IN LISTS ARGN)
    set(dst ${TETRASAND_SHADER_BUILD_DIR}/${rel})
    add_custom_command(OUTPUT ${dst}
      COMMAND ${CMAKE_COMMAND} -E copy_if_different ${PROJECT_SOURCE_DIR}/shaders/${rel} ${dst}
      DEPENDS ${PROJECT_SOURCE_DIR}/shaders/${rel} VERBATIM)
    list(APPEND outs ${dst})
    get_filename_component(rel_dir ${rel} DIRECTORY)
    install(FILES ${PROJECT_SOURCE_DIR}/shaders/${rel} DESTINATION share/tetrasand/shaders/${rel_dir})
  endforeach()
  add_custom_target(${target} ALL DEPENDS ${outs})
endfunction()

# Vendor headers the kernels include (today NanoVDB's PNanoVDB.h, from Debian's libnanovdb-dev):
# copied beside our shaders in the build tree and installed with them, so a binary that travels with
# its share/ folder (the GPU machine has no libnanovdb-dev) finds them.
function(tetrasand_add_vendor_shader_header target include_dir rel)
  set(dst ${TETRASAND_SHADER_BUILD_DIR}/${rel})
  add_custom_command(OUTPUT ${dst}
    COMMAND ${CMAKE_COMMAND} -E copy_if_different ${include_dir}/${rel} ${dst}
    DEPENDS ${include_dir}/${rel} VERBATIM)
  add_custom_target(${target} ALL DEPENDS ${dst})
  get_filename_component(rel_dir ${rel} DIRECTORY)
  install(FILES ${include_dir}/${rel} DESTINATION share/tetrasand/shaders/${rel_dir})
endfunction()
