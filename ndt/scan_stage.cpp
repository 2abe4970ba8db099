#include "scan_stage.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define COLOC_STAGE_AVX2 1
#endif

namespace coloc::ndt {

namespace {

inline void stageOne(const Eigen::Vector3f& point, const RunMotion& m, const StageBounds& b, StagedPoint& out) {
  const double x = point.x(), y = point.y(), z = point.z();
  const double r2 = x * x + y * y + z * z;
  if (r2 < b.lo || r2 > b.hi) {  // a NaN range is not cropped: it has no voxel below
    out.ok = false;
    return;
  }
  out.p = m.moves ? Eigen::Vector3f(static_cast<float>(m.c * x - m.s * y + m.dx), static_cast<float>(m.s * x + m.c * y + m.dy), point.z()) : point;
  out.ok = voxelOf(out.p.x(), out.p.y(), out.p.z(), b.inverse, out.key);
}

#ifdef COLOC_STAGE_AVX2
// voxelCoordinate for four values: floor(v) where -1999999999 <= v < 2e9 (exactly where voxelCoordinate
// gives floor(v): |floor(v)| < 2e9), else not valid (NaN included: its comparisons are false).
__attribute__((target("avx2"))) inline __m128i floors(__m256d v, __m256d& valid) {
  valid = _mm256_and_pd(_mm256_cmp_pd(v, _mm256_set1_pd(-1999999999.0), _CMP_GE_OQ), _mm256_cmp_pd(v, _mm256_set1_pd(2e9), _CMP_LT_OQ));
  const __m256d safe = _mm256_blendv_pd(_mm256_setzero_pd(), v, valid);
  return _mm256_cvttpd_epi32(_mm256_round_pd(safe, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
}

__attribute__((target("avx2"))) void stageRunAvx2(const Eigen::Vector3f* points, std::size_t n, const RunMotion& m, const StageBounds& b,
                                                  StagedPoint* out) {
  const __m256d lo = _mm256_set1_pd(b.lo), hi = _mm256_set1_pd(b.hi), inverse = _mm256_set1_pd(b.inverse);
  const __m256d c = _mm256_set1_pd(m.c), s = _mm256_set1_pd(m.s), dx = _mm256_set1_pd(m.dx), dy = _mm256_set1_pd(m.dy);
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const Eigen::Vector3f* p = points + i;
    const __m128 xf = _mm_setr_ps(p[0].x(), p[1].x(), p[2].x(), p[3].x()), yf = _mm_setr_ps(p[0].y(), p[1].y(), p[2].y(), p[3].y()),
                 zf = _mm_setr_ps(p[0].z(), p[1].z(), p[2].z(), p[3].z());
    const __m256d x = _mm256_cvtps_pd(xf), y = _mm256_cvtps_pd(yf), z = _mm256_cvtps_pd(zf);
    const __m256d r2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z));
    const __m256d cropped = _mm256_or_pd(_mm256_cmp_pd(r2, lo, _CMP_LT_OQ), _mm256_cmp_pd(r2, hi, _CMP_GT_OQ));
    __m128 mxf = xf, myf = yf;
    if (m.moves) {
      mxf = _mm256_cvtpd_ps(_mm256_add_pd(_mm256_sub_pd(_mm256_mul_pd(c, x), _mm256_mul_pd(s, y)), dx));
      myf = _mm256_cvtpd_ps(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(s, x), _mm256_mul_pd(c, y)), dy));
    }
    __m256d vx, vy, vz;
    const __m128i kx = floors(_mm256_mul_pd(_mm256_cvtps_pd(mxf), inverse), vx), ky = floors(_mm256_mul_pd(_mm256_cvtps_pd(myf), inverse), vy),
                  kz = floors(_mm256_mul_pd(z, inverse), vz);
    const int ok = _mm256_movemask_pd(_mm256_andnot_pd(cropped, _mm256_and_pd(vx, _mm256_and_pd(vy, vz))));
    alignas(16) float px[4], py[4], pz[4];
    alignas(16) std::int32_t ix[4], iy[4], iz[4];
    _mm_store_ps(px, mxf);
    _mm_store_ps(py, myf);
    _mm_store_ps(pz, zf);
    _mm_store_si128(reinterpret_cast<__m128i*>(ix), kx);
    _mm_store_si128(reinterpret_cast<__m128i*>(iy), ky);
    _mm_store_si128(reinterpret_cast<__m128i*>(iz), kz);
    for (int k = 0; k < 4; ++k) {
      StagedPoint& o = out[i + static_cast<std::size_t>(k)];
      o.p = Eigen::Vector3f(px[k], py[k], pz[k]);
      o.key.x = ix[k], o.key.y = iy[k], o.key.z = iz[k];
      o.ok = (ok >> k) & 1;
    }
  }
  for (; i < n; ++i) stageOne(points[i], m, b, out[i]);
}
#endif

}  // namespace

void stageRunPortable(const Eigen::Vector3f* points, std::size_t n, const RunMotion& motion, const StageBounds& bounds, StagedPoint* out) {
  for (std::size_t i = 0; i < n; ++i) stageOne(points[i], motion, bounds, out[i]);
}

bool stageRunVectorised() {
#ifdef COLOC_STAGE_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
}

void stageRun(const Eigen::Vector3f* points, std::size_t n, const RunMotion& motion, const StageBounds& bounds, StagedPoint* out) {
#ifdef COLOC_STAGE_AVX2
  if (stageRunVectorised()) return stageRunAvx2(points, n, motion, bounds, out);
#endif
  stageRunPortable(points, n, motion, bounds, out);
}

}  // namespace coloc::ndt
