#include "model/vector_kernel.hpp"

#include "model/input_error.hpp"
#include "model/libmvec_avx2.hpp"

namespace uphill {

bool CpuHasAvx2Fma() {
#if defined(__x86_64__)
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

bool VectorKernelAvailable(VectorKernel kernel) {
  return kernel != VectorKernel::kAvx2 || (UPHILL_LIBMVEC_AVX2 && CpuHasAvx2Fma());
}

const char* VectorKernelName(VectorKernel kernel) {
  if (kernel == VectorKernel::kAuto)
    kernel = VectorKernelAvailable(VectorKernel::kAvx2) ? VectorKernel::kAvx2 : VectorKernel::kScalar;
  return kernel == VectorKernel::kAvx2 ? "avx2+fma (libmvec)" : "scalar (libm)";
}

bool UseAvx2(VectorKernel kernel) {
  switch (kernel) {
    case VectorKernel::kAuto: return VectorKernelAvailable(VectorKernel::kAvx2);
    case VectorKernel::kScalar: return false;
    case VectorKernel::kAvx2:
      if (!VectorKernelAvailable(VectorKernel::kAvx2))
        throw InputError("kernel", "avx2+fma requested but not available on this CPU");
      return true;
  }
  return false;
}

}  // namespace uphill
