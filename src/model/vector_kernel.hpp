// VectorKernel: which implementation of a vectorised loop runs — the batch converter
// (batch_convert.hpp), the Monte Carlo's normal draws and window counts (propagation.hpp) and
// the release times of motion.hpp. One choice, one availability test, one error for all of them.
//
//   kScalar  the scalar code (libm), bit-identical to the model's scalar expressions where the
//            caller says so.
//   kAvx2    4-wide AVX2 + FMA with glibc's libmvec vector functions (within 4 ulp of the
//            correctly rounded result, libmvec's documented bound). Available where the CPU has
//            AVX2 and FMA and the build found libmvec (UPHILL_HAVE_LIBMVEC).
//   kAuto    kAvx2 where available, else kScalar.
#pragma once

namespace uphill {

enum class VectorKernel { kAuto, kScalar, kAvx2 };

// True where the CPU has AVX2 and FMA (__builtin_cpu_supports), whatever the build found.
bool CpuHasAvx2Fma();

// kAvx2: the CPU has AVX2 + FMA and the build found libmvec; kAuto and kScalar: always.
bool VectorKernelAvailable(VectorKernel kernel);

// "avx2+fma (libmvec)" or "scalar (libm)": what `kernel` (kAuto: what it resolves to) runs.
const char* VectorKernelName(VectorKernel kernel = VectorKernel::kAuto);

// Whether `kernel` runs the AVX2 code: kAuto resolves, kScalar never; kAvx2 where it is not
// available throws InputError("kernel", "avx2+fma requested but not available on this CPU").
bool UseAvx2(VectorKernel kernel);

}  // namespace uphill
