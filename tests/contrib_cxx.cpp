// contrib/psb_sparse.h and contrib/psb_condense.h, implementations included, compiled as C++: a
// build check beside build/test_sparse (the object is built, not linked).
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#define PSB_SPARSE_IMPLEMENTATION
#include "contrib/psb_sparse.h"
#define PSB_CONDENSE_IMPLEMENTATION
#include "contrib/psb_condense.h"

int contrib_cxx_sizes(void);
int contrib_cxx_sizes(void) { return (int)(sizeof(psb_sparse) + sizeof(psb_condense)); }
