/* A second translation unit for tests/test_sparse.c: contrib/psb_condense.h (and pscbranch.h)
   declared without their implementations, as in every file of a program but one. */
#include "pscbranch.h"
#include "contrib/psb_condense.h"

size_t condense_struct_size(void);
size_t condense_struct_size(void) { return sizeof(psb_condense); }
