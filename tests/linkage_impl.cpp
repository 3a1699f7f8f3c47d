// The implementation compiled as C++: catches C-only constructs and extern "C" mistakes.
#define PSCBRANCH_IMPLEMENTATION
#include "../pscbranch.h"
