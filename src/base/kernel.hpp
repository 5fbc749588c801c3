#pragma once
// Hot loops compiled twice: for x86-64-v3 (AVX2 and fused multiply-add, on every
// x86-64 CPU since 2013) and for the baseline, the loader choosing by the CPU it
// runs on. A fused multiply-add rounds once where a multiply and an add round
// twice, so results can differ between CPUs in the last bits; on one machine they
// never depend on the number of threads.
//
// A kernel must not throw (allocate nothing in one): g++ 12 compiles a call to
// cloned functions as a call that cannot throw, so an exception from a kernel
// passes every handler and ends in std::terminate.

// GCC only: clang 14 does not emit the plain symbol of a cloned function that other
// translation units call.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__)
#define INTERPATCH_KERNEL __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define INTERPATCH_KERNEL
#endif
