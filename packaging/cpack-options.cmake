# Read by cpack once per generator (CPACK_PROJECT_CONFIG_FILE). The DEB generator strips the
# binary and module itself when it moves their debug symbols into the -dbgsym package; stripping
# before that would leave that package empty, so only the tarball is stripped here.
if(CPACK_GENERATOR STREQUAL "TGZ")
  set(CPACK_STRIP_FILES ON)
endif()
