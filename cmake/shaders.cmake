# camhead_embed_shaders(TARGET SOURCES...)
#
# Compiles each GLSL compute shader to SPIR-V with glslangValidator at build
# time (a shader error fails the build) and emits it as a C array in a header,
# <name>_spv.h with `const uint32_t <name>_spv[]`, on TARGET's include path.
function(camhead_embed_shaders target)
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/generated_shaders)
  file(MAKE_DIRECTORY ${out_dir})
  set(headers)
  foreach(src IN LISTS ARGN)
    get_filename_component(name ${src} NAME_WE)
    get_filename_component(abs ${src} ABSOLUTE)
    get_filename_component(dir ${abs} DIRECTORY)
    set(header ${out_dir}/${name}_spv.h)
    add_custom_command(
      OUTPUT ${header}
      COMMAND ${GLSLANG_VALIDATOR} -V --target-env vulkan1.1 -I${dir} --vn ${name}_spv
              --depfile ${header}.d -o ${header} ${abs}
      DEPENDS ${abs}
      DEPFILE ${header}.d
      COMMENT "glslang ${name}.comp"
      VERBATIM)
    list(APPEND headers ${header})
  endforeach()
  add_custom_target(${target}_shaders DEPENDS ${headers})
  add_dependencies(${target} ${target}_shaders)
  target_include_directories(${target} PRIVATE ${out_dir})
endfunction()
