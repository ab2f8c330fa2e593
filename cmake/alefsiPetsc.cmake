# Finds PETSc (pkg-config module PETSc) and MPI, and defines the imported target alefsi::petsc:
# alefsi::alefsi with PETSc's solver policies (la/petsc.hpp) usable. Used by alefsi's own
# CMakeLists.txt and by the installed alefsiConfig.cmake. Debian/Ubuntu: apt install petsc-dev
# libopenmpi-dev openmpi-bin pkg-config.
#
#   alefsi_find_petsc(<found-var>)   sets <found-var> to TRUE or FALSE in the caller
function(alefsi_find_petsc found_var)
  if(TARGET alefsi::petsc_libraries)
    set(${found_var} TRUE PARENT_SCOPE)
    return()
  endif()
  set(${found_var} FALSE PARENT_SCOPE)
  find_package(PkgConfig QUIET)
  if(NOT PKG_CONFIG_FOUND)
    return()
  endif()
  # 3.18: MatSetPreallocationCOO with PetscCount; the real, double-precision build (la/petsc.hpp
  # static_asserts it)
  pkg_check_modules(ALEFSI_PETSC QUIET IMPORTED_TARGET GLOBAL PETSc>=3.18)
  if(NOT ALEFSI_PETSC_FOUND)
    return()
  endif()
  set(MPI_CXX_SKIP_MPICXX ON)  # the C API only (the C++ bindings are deprecated)
  find_package(MPI QUIET COMPONENTS CXX)
  if(NOT MPI_CXX_FOUND)
    return()
  endif()
  set_target_properties(MPI::MPI_CXX PROPERTIES IMPORTED_GLOBAL TRUE)  # seen from every directory
  add_library(alefsi::petsc_libraries INTERFACE IMPORTED GLOBAL)
  set_target_properties(alefsi::petsc_libraries PROPERTIES INTERFACE_LINK_LIBRARIES "PkgConfig::ALEFSI_PETSC;MPI::MPI_CXX")
  set(ALEFSI_PETSC_VERSION ${ALEFSI_PETSC_VERSION} PARENT_SCOPE)
  set(${found_var} TRUE PARENT_SCOPE)
endfunction()
