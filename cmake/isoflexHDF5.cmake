# HDF5's C library (results.h5, io/hdf5_results.cpp) as the imported target isoflex::hdf5; sets
# isoflex_HDF5_FOUND. Looked for by name, as isoflexSuiteSparse.cmake does, by the build and again
# by isoflexConfig.cmake in a project that links the installed package (io links it). Not
# find_package(HDF5): FindHDF5 test-compiles a C file (a configure error in a project without the
# C language, such as this one and its consumers) and its HDF5::HDF5 carries the whole link line of
# Debian's h5cc (libcurl, libcrypto, libsz, the static libpthread.a and libdl.a), where libhdf5 is
# all isoflex calls. Debian's serial HDF5 (libhdf5-dev) has its headers in include/hdf5/serial and
# the library as libhdf5_serial (also lib/<arch>/hdf5/serial/libhdf5). The cache variables have
# the prefix ISOFLEX_: FindHDF5 in the same project has its own HDF5_* ones.
find_path(ISOFLEX_HDF5_INCLUDE_DIR hdf5.h PATH_SUFFIXES hdf5/serial)
find_library(ISOFLEX_HDF5_LIBRARY NAMES hdf5_serial hdf5 PATH_SUFFIXES hdf5/serial)
if(ISOFLEX_HDF5_INCLUDE_DIR AND ISOFLEX_HDF5_LIBRARY)
  set(isoflex_HDF5_FOUND TRUE)
  if(NOT TARGET isoflex::hdf5)
    # An imported target's include directories are system ones: HDF5's headers stay out of the
    # project's -Werror.
    add_library(isoflex::hdf5 INTERFACE IMPORTED)
    set_target_properties(isoflex::hdf5 PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${ISOFLEX_HDF5_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "${ISOFLEX_HDF5_LIBRARY}")
  endif()
else()
  set(isoflex_HDF5_FOUND FALSE)
endif()
