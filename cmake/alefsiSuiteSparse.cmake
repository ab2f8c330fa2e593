# Finds the parts of SuiteSparse that alefsi's solver policies use (UMFPACK, CHOLMOD, through
# Eigen's wrappers) and defines the imported target alefsi::suitesparse. Used by alefsi's own
# CMakeLists.txt and by the installed alefsiConfig.cmake (so that a downstream project finds
# the same libraries). Debian/Ubuntu: apt install libsuitesparse-dev libopenblas-dev.
#
#   alefsi_find_suitesparse(<found-var>)   sets <found-var> to TRUE or FALSE in the caller
#
# The BLAS: the shared SuiteSparse libraries bring their own dependency on libblas.so.3
# (Debian: an alternative, OpenBLAS when libopenblas0 is installed). When OpenBLAS is found it
# is linked as well; loaded before libblas.so.3, its dgemm then serves UMFPACK and CHOLMOD
# whatever libblas.so.3 points to (Debian's reference BLAS is several times slower).
function(alefsi_find_suitesparse found_var)
  if(TARGET alefsi::suitesparse)
    set(${found_var} TRUE PARENT_SCOPE)
    return()
  endif()
  find_path(ALEFSI_SUITESPARSE_INCLUDE_DIR umfpack.h PATH_SUFFIXES suitesparse
            DOC "Directory of umfpack.h and cholmod.h")
  set(libs "")
  set(ok TRUE)
  if(NOT ALEFSI_SUITESPARSE_INCLUDE_DIR OR NOT EXISTS "${ALEFSI_SUITESPARSE_INCLUDE_DIR}/cholmod.h")
    set(ok FALSE)
  endif()
  foreach(lib umfpack cholmod amd colamd suitesparseconfig)
    string(TOUPPER ${lib} LIB)
    find_library(ALEFSI_${LIB}_LIBRARY ${lib} DOC "SuiteSparse library ${lib}")
    if(ALEFSI_${LIB}_LIBRARY)
      list(APPEND libs ${ALEFSI_${LIB}_LIBRARY})
    else()
      set(ok FALSE)
    endif()
  endforeach()
  if(NOT ok)
    set(${found_var} FALSE PARENT_SCOPE)
    return()
  endif()
  set(BLA_VENDOR OpenBLAS)
  find_package(BLAS QUIET)
  add_library(alefsi::suitesparse INTERFACE IMPORTED)
  set_target_properties(alefsi::suitesparse PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${ALEFSI_SUITESPARSE_INCLUDE_DIR}")
  if(BLAS_FOUND)
    list(APPEND libs ${BLAS_LIBRARIES})
  endif()
  set_target_properties(alefsi::suitesparse PROPERTIES INTERFACE_LINK_LIBRARIES "${libs}")
  set(${found_var} TRUE PARENT_SCOPE)
endfunction()
