# SuiteSparse (UMFPACK for the sparse LU, CHOLMOD for sparse Cholesky) as the imported target
# isoflex::suitesparse; sets isoflex_SuiteSparse_FOUND. Debian 12 ships neither a CMake config nor
# a pkg-config file for it, so the libraries are looked for by name: by the build, and again by
# isoflexConfig.cmake (this file is installed next to it) in a project that links the installed
# package. Looking again there rather than exporting the build's absolute paths: the consumer gets
# the libraries of its own machine and CMAKE_PREFIX_PATH, and a missing SuiteSparse fails
# find_package(isoflex) with a message instead of the consumer's link step.
find_path(SUITESPARSE_INCLUDE_DIR umfpack.h PATH_SUFFIXES suitesparse)
find_library(UMFPACK_LIBRARY umfpack)
find_library(CHOLMOD_LIBRARY cholmod)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
if(SUITESPARSE_INCLUDE_DIR AND UMFPACK_LIBRARY AND CHOLMOD_LIBRARY AND SUITESPARSECONFIG_LIBRARY)
  set(isoflex_SuiteSparse_FOUND TRUE)
  if(NOT TARGET isoflex::suitesparse)
    # An imported target's include directories are system ones: SuiteSparse's headers stay out of
    # the project's -Werror.
    add_library(isoflex::suitesparse INTERFACE IMPORTED)
    set_target_properties(isoflex::suitesparse PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${SUITESPARSE_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES
        "${UMFPACK_LIBRARY};${CHOLMOD_LIBRARY};${SUITESPARSECONFIG_LIBRARY}")
  endif()
else()
  set(isoflex_SuiteSparse_FOUND FALSE)
endif()
