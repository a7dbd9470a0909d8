// Private: whether kernels can be compiled once per instruction set and bound when the program
// loads (GCC's function multiversioning, [[gnu::target("...")]] overloads, an ifunc on Linux).
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define ISOHEX_HAVE_FMV 1
#else
#define ISOHEX_HAVE_FMV 0
#endif
