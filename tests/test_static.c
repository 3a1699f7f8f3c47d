/* PSCBRANCH_STATIC: a private copy of the library in this file, most of it unused, must compile
   without warnings and work. */
#define PSCBRANCH_STATIC
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"

int main(void)
{
    psb_options o = psb_options_resolve(NULL);
    psb_branch_options b = psb_branch_options_resolve(NULL, NULL);
    CHECK(o.switch_n_dir == 20 && b.n_dir == 20);
    CHECK(psb_result_string(PSB_ERR_NULL)[0] == 'P');
    return HARNESS_END();
}
