# PETSc (the Krylov solvers and algebraic multigrid of solve/petsc, docs/theory/solvers.md) and
# the MPI it is built on, as the imported target isoflex::petsc; sets isoflex_PETSc_FOUND. From
# Debian's pkg-config files: PETSc.pc (petsc-dev, the real double-precision build with 32-bit
# indices) names PETSc's own include folder only, mpi-c.pc (the default MPI, OpenMPI) the folder
# of mpi.h that PETSc's headers include. Only the loadable module isoflex_petsc links it: a
# program that links PETSc loads its ~100 libraries (OpenMPI, hypre, MUMPS, ScaLAPACK, Trilinos)
# at every start, 60–80 ms and 30 MB per process.
find_package(PkgConfig QUIET)
set(isoflex_PETSc_FOUND FALSE)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(ISOFLEX_PETSC QUIET PETSc)
  pkg_check_modules(ISOFLEX_MPI QUIET mpi-c)
  if(ISOFLEX_PETSC_FOUND AND ISOFLEX_MPI_FOUND)
    set(isoflex_PETSc_FOUND TRUE)
    if(NOT TARGET isoflex::petsc)
      # System include folders: PETSc's and MPI's headers stay out of the project's -Werror.
      add_library(isoflex::petsc INTERFACE IMPORTED)
      set_target_properties(isoflex::petsc PROPERTIES
        INTERFACE_INCLUDE_DIRECTORIES "${ISOFLEX_PETSC_INCLUDE_DIRS};${ISOFLEX_MPI_INCLUDE_DIRS}"
        INTERFACE_LINK_DIRECTORIES "${ISOFLEX_PETSC_LIBRARY_DIRS};${ISOFLEX_MPI_LIBRARY_DIRS}"
        INTERFACE_LINK_LIBRARIES "${ISOFLEX_PETSC_LIBRARIES};${ISOFLEX_MPI_LIBRARIES}")
    endif()
  endif()
endif()
