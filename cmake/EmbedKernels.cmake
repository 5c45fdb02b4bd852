# Embeds kernels/*.cl into the binary as byte arrays, so the program runs from any
# directory and kernel build logs keep the real file names and line numbers.
function(voxbreast_embed_kernels target)
  set(out_dir ${CMAKE_BINARY_DIR}/generated/kernels)
  set(sources ${ARGN})
  set(outputs)
  foreach(src IN LISTS sources)
    get_filename_component(name ${src} NAME_WE)
    set(out ${out_dir}/${name}_cl.cpp)
    add_custom_command(OUTPUT ${out}
      COMMAND ${CMAKE_COMMAND} -DINPUT=${CMAKE_CURRENT_SOURCE_DIR}/${src} -DOUTPUT=${out} -DNAME=${name}
              -P ${PROJECT_SOURCE_DIR}/cmake/EmbedFile.cmake
      DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${src} ${PROJECT_SOURCE_DIR}/cmake/EmbedFile.cmake
      COMMENT "Embedding kernel ${src}")
    list(APPEND outputs ${out})
    list(APPEND names ${name})
  endforeach()
  # Registry: one table of (file name, text) pairs.
  set(reg ${out_dir}/kernel_registry.cpp)
  set(decls "")
  set(entries "")
  foreach(name IN LISTS names)
    string(APPEND decls "extern const char* const kernel_${name}_cl;\n")
    string(APPEND entries "    {\"${name}.cl\", kernel_${name}_cl},\n")
  endforeach()
  file(WRITE ${reg}.in "// Generated: table of embedded OpenCL sources.\n#include <utility>\n#include <vector>\nnamespace vb::kernels {\n${decls}const std::vector<std::pair<const char*, const char*>>& embedded_sources() {\n  static const std::vector<std::pair<const char*, const char*>> table = {\n${entries}  };\n  return table;\n}\n}  // namespace vb::kernels\n")
  configure_file(${reg}.in ${reg} COPYONLY)
  add_library(${target} STATIC ${outputs} ${reg})
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
