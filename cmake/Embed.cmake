# nelf_embed_files(TARGET_NAME OUTPUT_CPP FILES...)
# Generates OUTPUT_CPP defining nelf::embedded::<TARGET_NAME>(), a list of {file name, contents}.
# The contents are emitted as byte arrays so any file (GLSL, TOML) round-trips exactly.
function(nelf_embed_files name output)
  set(files ${ARGN})
  add_custom_command(OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DNAME=${name} -DOUTPUT=${output} "-DFILES=${files}"
            -P ${CMAKE_SOURCE_DIR}/cmake/EmbedScript.cmake
    DEPENDS ${files} ${CMAKE_SOURCE_DIR}/cmake/EmbedScript.cmake
    COMMENT "Embedding ${name}" VERBATIM)
endfunction()
