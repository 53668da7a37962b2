# cmake -DVALIDATOR=glslangValidator -DDIR=variants -DSTAMP=file -P ValidateShaderVariants.cmake
# Validates and links each program nelf_write_shader_variants wrote into DIR (DIR/programs.txt);
# fails on the first error with glslangValidator's message, else touches STAMP.
file(STRINGS ${DIR}/programs.txt programs)
list(LENGTH programs count)
if(count EQUAL 0)
  message(FATAL_ERROR "no shader programs listed in ${DIR}/programs.txt")
endif()
foreach(program ${programs})
  execute_process(COMMAND ${VALIDATOR} -l ${DIR}/${program}.vert ${DIR}/${program}.frag
                  RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "shader program ${program} (${DIR}/${program}.vert + .frag) is invalid:\n${output}")
  endif()
endforeach()
file(TOUCH ${STAMP})
message(STATUS "${count} shader programs validated")
