# Finds gmsh's C++ API (gmsh.h, libgmsh; GPL) and defines the imported target
# alefsi::gmsh_libraries, behind alefsi::gmsh (the 3D mesher and remesher:
# mesh/generate/gmsh_mesher.hpp, sim/remesher3d.hpp). Used by alefsi's own CMakeLists.txt and by
# the installed alefsiConfig.cmake. Debian/Ubuntu: apt install libgmsh-dev.
#
#   alefsi_find_gmsh(<found-var>)   sets <found-var> to TRUE or FALSE in the caller
function(alefsi_find_gmsh found_var)
  if(TARGET alefsi::gmsh_libraries)
    set(${found_var} TRUE PARENT_SCOPE)
    return()
  endif()
  set(${found_var} FALSE PARENT_SCOPE)
  find_path(ALEFSI_GMSH_INCLUDE_DIR gmsh.h)
  find_library(ALEFSI_GMSH_LIBRARY gmsh)
  if(NOT ALEFSI_GMSH_INCLUDE_DIR OR NOT ALEFSI_GMSH_LIBRARY)
    return()
  endif()
  # 4.8: the size callback with four arguments and OpenCASCADE booleans, as the mesher uses them
  file(STRINGS "${ALEFSI_GMSH_INCLUDE_DIR}/gmsh.h" version_line REGEX "#define GMSH_API_VERSION \"")
  string(REGEX MATCH "[0-9]+\\.[0-9]+(\\.[0-9]+)?" version "${version_line}")
  if(NOT version OR version VERSION_LESS 4.8)
    message(STATUS "alefsi: gmsh ${version} at ${ALEFSI_GMSH_INCLUDE_DIR} is older than 4.8: not used")
    return()
  endif()
  add_library(alefsi::gmsh_libraries INTERFACE IMPORTED GLOBAL)
  set_target_properties(alefsi::gmsh_libraries PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${ALEFSI_GMSH_INCLUDE_DIR}"
                                                          INTERFACE_LINK_LIBRARIES "${ALEFSI_GMSH_LIBRARY}")
  set(ALEFSI_GMSH_VERSION ${version} PARENT_SCOPE)
  set(${found_var} TRUE PARENT_SCOPE)
endfunction()
