# The Vulkan shaders: every entry shader of kernels/vulkan/ compiled by glslang to SPIR-V at
# build time in four variants (single and double precision, each with storage reads or with
# texel reads, -DSF_TEXEL_READS: kernels/vulkan/ensemble_layout.h), and embedded as uint32
# words in the program (cmake/embed_spirv.cmake), so that it needs no shader files at run time.
# An entry is NAME:SOURCE[:DEFINE[:ENV]]: kernels/vulkan/SOURCE.comp compiled with -DDEFINE (one
# file may hold several entry shaders, chosen with -D switches; DEFINE+DEFINE for two) for Vulkan ENV (vulkan1.0 by
# default; vulkan1.1 for SPIR-V 1.3's subgroup operations, which the host uses only on a 1.1
# device that has them). glslang defines VULKAN
# itself (kernels/shared/dialect.h's Vulkan branch). Rebuilt when a source or any header of
# kernels/vulkan/ or kernels/shared/ changes.
find_program(SIGMAFEM_GLSLANG glslangValidator)
if(NOT SIGMAFEM_GLSLANG)
  message(FATAL_ERROR "glslangValidator not found: the Vulkan shaders are compiled with it at "
                      "build time (on Debian: apt-get install glslang-tools)")
endif()

# sigmafem_compile_glsl(<output .cpp> ENTRIES <NAME:SOURCE[:DEFINE]>...)
function(sigmafem_compile_glsl output)
  cmake_parse_arguments(ARG "" "" "ENTRIES" ${ARGN})
  set(_shared ${PROJECT_SOURCE_DIR}/kernels/shared)
  set(_vulkan ${PROJECT_SOURCE_DIR}/kernels/vulkan)
  file(GLOB _headers CONFIGURE_DEPENDS ${_shared}/*.h ${_vulkan}/*.h)
  set(_table "")
  set(_outputs "")
  foreach(_entry IN LISTS ARG_ENTRIES)
    string(REPLACE ":" ";" _parts "${_entry}")
    list(GET _parts 0 _name)
    list(GET _parts 1 _source)
    set(_defines "")
    set(_env vulkan1.0)
    list(LENGTH _parts _count)
    if(_count GREATER 2)
      list(GET _parts 2 _define)
      string(REPLACE "+" ";-D" _defines "-D${_define}")
    endif()
    if(_count GREATER 3)
      list(GET _parts 3 _env)
    endif()
    foreach(_precision single double single_texel double_texel)
      set(_spv ${PROJECT_BINARY_DIR}/generated/spirv/${_name}_${_precision}.spv)
      set(_precision_define "")
      if(_precision MATCHES "^double")
        list(APPEND _precision_define "-DSF_USE_DOUBLE")
      endif()
      if(_precision MATCHES "_texel$")
        list(APPEND _precision_define "-DSF_TEXEL_READS")
      endif()
      add_custom_command(
        OUTPUT ${_spv}
        COMMAND ${SIGMAFEM_GLSLANG} -V --target-env ${_env} -S comp --quiet ${_defines}
                ${_precision_define} -I${_shared} -I${_vulkan} -o ${_spv} ${_vulkan}/${_source}.comp
        DEPENDS ${_vulkan}/${_source}.comp ${_headers}
        COMMENT "glslang: ${_name} (${_precision}) from kernels/vulkan/${_source}.comp"
        VERBATIM)
      list(APPEND _outputs ${_spv})
      list(APPEND _table "${_name}:${_precision}:${_spv}")
    endforeach()
  endforeach()
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output} "-DSHADERS=${_table}"
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_spirv.cmake
    DEPENDS ${_outputs} ${PROJECT_SOURCE_DIR}/cmake/embed_spirv.cmake
    COMMENT "Embedding the Vulkan shaders"
    VERBATIM)
endfunction()
