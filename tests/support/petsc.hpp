#pragma once
// Tests of the PETSc solvers (solve/krylov_solver.hpp). The build has the PETSc module
// (scripts/setup.sh installs petsc-dev): a module that does not load is a failure, not a skip.
// Under AddressSanitizer they skip: PETSc, OpenMPI and their libraries are not instrumented, and
// what the tests state is checked by the Release suite.
#include <gtest/gtest.h>

#include <string>

#include "isoflex/solve/krylov_solver.hpp"
#include "support/sanitizers.hpp"

#if defined(ISOFLEX_TEST_ASAN)
#define ISOFLEX_REQUIRE_PETSC() \
  GTEST_SKIP() << "PETSc's libraries are not instrumented: checked by the Release suite"
#else
#define ISOFLEX_REQUIRE_PETSC()                          \
  do {                                                   \
    std::string petsc_why;                               \
    if (!isoflex::solve::krylov_available(&petsc_why)) { \
      FAIL() << petsc_why;                               \
    }                                                    \
  } while (false)
#endif
