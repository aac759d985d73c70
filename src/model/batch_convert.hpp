// Batch conversion kernels: the closed forms of the model evaluated for many configurations at
// once, arrays in, arrays out (structure of arrays, one array per quantity).
//
// Why a separate path: the Monte Carlo propagation (propagation.hpp) and `uphill bench convert`
// evaluate the closed forms 10^6–10^7 times. Through Rails/Scene each evaluation is dominated by
// scalar libm atan2 and the objects' set-up; here the same formulas run 4 lanes at a time using glibc's libmvec
// AVX2 variants (_ZGVdN4v_atan, _ZGVdN4v_tan, ≤ 4 ulp) when the CPU has AVX2 + FMA, chosen at run
// time, with a scalar fallback that evaluates the model's own expressions (bit for bit those of
// Rails, SpheroidOnLineRails, spheroid_on_rods_closed_forms.hpp and DoubleConeOnLineRails).
//
// Formulas, per element (docs/physics.md "Frame and apparatus", "Spheroid on line rails",
// "Round rods", "Double cone"; SI units: metres, radians):
//   rails from L, H, D    Lh = L (LConvention::kHorizontal) or sqrt((L − s)(L + s)), s = hypot(H, D/2)
//                         B = tanθ = H/Lh,  T = tan(α/2) = D/(2·Lh)
//                         θ = atan(B), α = 2·atan(T), φ = atan(T/sqrt(1 + B²))   [= atan2 forms]
//   rails from θ, α       B = tanθ, T = tan(α/2), φ as above
//   sphere, spheroid      A = a·T/b,  x_eq = a·B/(A·sqrt(A² + B²)),  x_max = sqrt(a² + (b/T)²)
//     on rods r > 0       x_eq(r), x_max(r) of spheroid_on_rods_closed_forms.hpp
//                         (a sphere on rods is the sphere of radius R + r on line rails: pass
//                         a = b = R + r and no rods, as Scene does)
//   double cone           x_fall = h/T,  θ0 = atan((R/h)·T),  Q = 1 + B² − (R/h)²·T²
//
// Contract:
//   - Domain as in the model (L, D, a, b, R, h > 0; H ≥ 0; kAlongRail needs L > hypot(H, D/2);
//     0 ≤ θ < π/2, 0 < α < π; r > 0 when given). The kernels do not check: outside the domain they
//     return whatever IEEE arithmetic gives (NaN, ±inf, or a meaningless number) and never trap or
//     throw, so a caller (the Monte Carlo) can screen its draws before or after, in bulk.
//   - Accuracy against the scalar model: kScalar is bit-identical to it; kAvx2 agrees within a few
//     ulp (libmvec's ≤ 4 ulp for the angles, sqrt(fma) for hypot, one more rounding here and
//     there): tests/batch_convert_test.cpp checks ≤ 8–24 units of 2^-53 relative (≤ 2.7e-15), more
//     along a rail where L − hypot(H, D/2) amplifies hypot's rounding. Against the 60-digit
//     references both reach ≈ 3e-16 (`uphill bench convert`).
//   - Each element's result depends only on that element's inputs (a tail shorter than a vector is
//     padded, not sent through another code path), so results do not depend on n or on where an
//     element sits in its array: a reordered or compacted batch gives the same numbers.
//   - Arrays of one call may be the same array only where noted; no allocation, no virtual
//     dispatch: one indirect branch per call to pick the kernel.
#pragma once

#include <cstddef>
#include <cstdint>

#include "model/rails.hpp"
#include "model/vector_kernel.hpp"

namespace uphill {

// Outputs of the rails stage, n values each. A null pointer means "not wanted".
struct RailsArrays {
  double* theta = nullptr;           // θ, rad
  double* alpha = nullptr;           // α, rad
  double* phi = nullptr;             // φ, rad (3-D half angle between the rails)
  double* tan_theta = nullptr;       // B = tanθ
  double* tan_half_alpha = nullptr;  // T = tan(α/2)
};

// Rails from crossbar measurements L, H, D (metres) with the given L convention.
void RailsFromApparatusBatch(std::size_t n, const double* L, const double* H, const double* D,
                             LConvention convention, const RailsArrays& out,
                             VectorKernel kernel = VectorKernel::kAuto);

// Rails from angles θ, α (radians). out.theta/out.alpha, if given, receive copies.
void RailsFromAnglesBatch(std::size_t n, const double* theta, const double* alpha,
                          const RailsArrays& out, VectorKernel kernel = VectorKernel::kAuto);

// Sphere (a = b = R) or spheroid: x_eq and x_max (metres; either may be null). rod_radius null:
// line rails; otherwise the rods' radii (> 0), closed forms of spheroid_on_rods_closed_forms.hpp.
void SpheroidBatch(std::size_t n, const double* a, const double* b, const double* rod_radius,
                   const double* tan_theta, const double* tan_half_alpha, double* x_eq,
                   double* x_max, VectorKernel kernel = VectorKernel::kAuto);

// Double cone (base radius R, half-length h) on line rails: x_fall = h·cot(α/2) (m), θ0 (rad),
// and Q = 1 + tan²θ − (R/h)²tan²(α/2) (the closed form and the scene need Q > 0). Any output may
// be null.
void DoubleConeBatch(std::size_t n, const double* R, const double* h, const double* tan_theta,
                     const double* tan_half_alpha, double* x_fall, double* theta0, double* q,
                     VectorKernel kernel = VectorKernel::kAuto);

// The converter's common case in one pass: crossbar L, H, D (metres, horizontal convention) to
// θ, α (rad) and X = x_eq (m) of one spheroid (semi-axes a, b, m) on line rails. Outputs may be
// null. kScalar: the model's expressions, bit for bit. kAvx2: the same quantities arranged for two
// divisions per configuration (X = 2b·H·L/(D·sqrt((aD/2b)² + H²)), θ = atan(H·(1/L)), …), within
// a few ulp of the model. This is the path `uphill bench convert` times.
void ConvertApparatusBatch(std::size_t n, const double* L, const double* H, const double* D,
                           double a, double b, double* theta, double* alpha, double* x_eq,
                           VectorKernel kernel = VectorKernel::kAuto);

}  // namespace uphill
