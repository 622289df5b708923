// 8-wide float/int vectors for the traversal kernels (internal to the accel module). Included
// inside `namespace toonray::accel::<isa>` by kernels_sse.cpp and kernels_avx2.cpp: with
// TOONRAY_ACCEL_AVX2 they are single AVX2 registers, otherwise pairs of SSE registers. Every
// operation is one IEEE operation per lane (no fused multiply-add, no reciprocal estimates), so
// lanes compute exactly what scalar code computes. Comparisons are ordered: false with NaN, as
// in C++. min(a, b) and max(a, b) return b when either is NaN (the SSE/AVX rule: a if a < b,
// else b), which the box tests use to ignore NaN distances. Masks (vm8) may carry meaning in
// their sign bits only (as_mask): movemask, blends and bitwise combinations look at nothing
// else.

#define TR_INLINE inline __attribute__((always_inline))

#ifdef TOONRAY_ACCEL_AVX2

struct vf8 {
    __m256 m;
};
struct vm8 {
    __m256 m;
};
struct vi8 {
    __m256i m;
};

TR_INLINE vf8 load8(const float* p) { return {_mm256_load_ps(p)}; }
TR_INLINE vf8 loadu8(const float* p) { return {_mm256_loadu_ps(p)}; }
TR_INLINE vf8 load4x2(const float* lo, const float* hi) {
    return {_mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(lo)), _mm_load_ps(hi), 1)};
}
TR_INLINE void store8(float* p, vf8 a) { _mm256_store_ps(p, a.m); }
TR_INLINE vf8 set1(float f) { return {_mm256_set1_ps(f)}; }
TR_INLINE vf8 bcast(const float* p) { return {_mm256_broadcast_ss(p)}; }
TR_INLINE vf8 operator+(vf8 a, vf8 b) { return {_mm256_add_ps(a.m, b.m)}; }
TR_INLINE vf8 operator-(vf8 a, vf8 b) { return {_mm256_sub_ps(a.m, b.m)}; }
TR_INLINE vf8 operator*(vf8 a, vf8 b) { return {_mm256_mul_ps(a.m, b.m)}; }
TR_INLINE vf8 operator/(vf8 a, vf8 b) { return {_mm256_div_ps(a.m, b.m)}; }
TR_INLINE vf8 vmin(vf8 a, vf8 b) { return {_mm256_min_ps(a.m, b.m)}; }
#ifdef TOONRAY_ACCEL_FMA
// Only where rounding once is accounted for (the box tests), never in the triangle tests.
TR_INLINE vf8 fmadd(vf8 a, vf8 b, vf8 c) { return {_mm256_fmadd_ps(a.m, b.m, c.m)}; }
// a * b + c rounded once, as std::fma: what the other builds compute of the fused box test.
TR_INLINE vf8 exact_fmadd(vf8 a, vf8 b, vf8 c) { return fmadd(a, b, c); }
#else
#error "the AVX2 kernels are compiled with FMA (kernels_avx2.cpp, kernels_avx512.cpp)"
#endif
TR_INLINE vf8 vmax(vf8 a, vf8 b) { return {_mm256_max_ps(a.m, b.m)}; }
TR_INLINE vf8 vabs(vf8 a) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.m)}; }
TR_INLINE vm8 operator<(vf8 a, vf8 b) { return {_mm256_cmp_ps(a.m, b.m, _CMP_LT_OQ)}; }
TR_INLINE vm8 operator<=(vf8 a, vf8 b) { return {_mm256_cmp_ps(a.m, b.m, _CMP_LE_OQ)}; }
TR_INLINE vm8 operator>(vf8 a, vf8 b) { return {_mm256_cmp_ps(a.m, b.m, _CMP_GT_OQ)}; }
TR_INLINE vm8 operator>=(vf8 a, vf8 b) { return {_mm256_cmp_ps(a.m, b.m, _CMP_GE_OQ)}; }
TR_INLINE vm8 operator==(vf8 a, vf8 b) { return {_mm256_cmp_ps(a.m, b.m, _CMP_EQ_OQ)}; }
TR_INLINE vm8 operator&(vm8 a, vm8 b) { return {_mm256_and_ps(a.m, b.m)}; }
TR_INLINE vm8 operator|(vm8 a, vm8 b) { return {_mm256_or_ps(a.m, b.m)}; }
TR_INLINE vm8 andnot(vm8 a, vm8 b) { return {_mm256_andnot_ps(a.m, b.m)}; }  // ~a & b
TR_INLINE int movemask(vm8 a) { return _mm256_movemask_ps(a.m); }
TR_INLINE vm8 as_mask(vf8 a) { return {a.m}; }  // the sign bits are the mask
TR_INLINE vm8 not_mask(vm8 a) {
    return {_mm256_xor_ps(a.m, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))};
}
TR_INLINE vm8 mask_from_bits(int bits) {
    const __m256i lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return {_mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits), lane), lane))};
}
TR_INLINE vf8 select(vm8 m, vf8 a, vf8 b) {
    return {_mm256_blendv_ps(b.m, a.m, m.m)};
}  // m ? a : b
TR_INLINE vi8 loadi8(const std::uint32_t* p) {
    return {_mm256_load_si256(reinterpret_cast<const __m256i*>(p))};
}
TR_INLINE void storei8(std::uint32_t* p, vi8 a) {
    _mm256_store_si256(reinterpret_cast<__m256i*>(p), a.m);
}
TR_INLINE vi8 seti1(std::uint32_t v) { return {_mm256_set1_epi32(static_cast<int>(v))}; }
TR_INLINE vm8 lt_signed(vi8 a, vi8 b) {
    return {_mm256_castsi256_ps(_mm256_cmpgt_epi32(b.m, a.m))};
}
TR_INLINE vm8 eqi(vi8 a, vi8 b) { return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(a.m, b.m))}; }
TR_INLINE vi8 selecti(vm8 m, vi8 a, vi8 b) {
    return {_mm256_castps_si256(
        _mm256_blendv_ps(_mm256_castsi256_ps(b.m), _mm256_castsi256_ps(a.m), m.m))};
}
TR_INLINE float hmin(vf8 a) {
    __m128 m = _mm_min_ps(_mm256_castps256_ps128(a.m), _mm256_extractf128_ps(a.m, 1));
    m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    m = _mm_min_ss(m, _mm_movehdup_ps(m));
    return _mm_cvtss_f32(m);
}
TR_INLINE float hmax(vf8 a) {
    __m128 m = _mm_max_ps(_mm256_castps256_ps128(a.m), _mm256_extractf128_ps(a.m, 1));
    m = _mm_max_ps(m, _mm_movehl_ps(m, m));
    m = _mm_max_ss(m, _mm_movehdup_ps(m));
    return _mm_cvtss_f32(m);
}

#else  // two SSE registers

struct vf8 {
    __m128 l, h;
};
struct vm8 {
    __m128 l, h;
};
struct vi8 {
    __m128i l, h;
};

TR_INLINE vf8 load8(const float* p) { return {_mm_load_ps(p), _mm_load_ps(p + 4)}; }
TR_INLINE vf8 loadu8(const float* p) { return {_mm_loadu_ps(p), _mm_loadu_ps(p + 4)}; }
TR_INLINE vf8 load4x2(const float* lo, const float* hi) {
    return {_mm_load_ps(lo), _mm_load_ps(hi)};
}
TR_INLINE void store8(float* p, vf8 a) {
    _mm_store_ps(p, a.l);
    _mm_store_ps(p + 4, a.h);
}
TR_INLINE vf8 set1(float f) { return {_mm_set1_ps(f), _mm_set1_ps(f)}; }
TR_INLINE vf8 bcast(const float* p) { return set1(*p); }
#define TR_BIN(op, fn) \
    TR_INLINE vf8 op(vf8 a, vf8 b) { return {fn(a.l, b.l), fn(a.h, b.h)}; }
TR_BIN(operator+, _mm_add_ps)
TR_BIN(operator-, _mm_sub_ps)
TR_BIN(operator*, _mm_mul_ps)
TR_BIN(operator/, _mm_div_ps)
TR_BIN(vmin, _mm_min_ps)
TR_BIN(vmax, _mm_max_ps)
#undef TR_BIN
// a * b + c rounded once, lane by lane through std::fma (the CPU's fused multiply-add where it
// has one, else the library's exact emulation): the AVX2 kernels' fused box test, which only
// the refusal of hits (held_to_box in watertight.h) computes here.
TR_INLINE vf8 exact_fmadd(vf8 a, vf8 b, vf8 c) {
    alignas(16) float x[8], y[8], z[8];
    store8(x, a);
    store8(y, b);
    store8(z, c);
    for (int i = 0; i < 8; ++i) x[i] = std::fma(x[i], y[i], z[i]);
    return load8(x);
}
TR_INLINE vf8 vabs(vf8 a) {
    const __m128 s = _mm_set1_ps(-0.0f);
    return {_mm_andnot_ps(s, a.l), _mm_andnot_ps(s, a.h)};
}
#define TR_CMP(op, fn) \
    TR_INLINE vm8 op(vf8 a, vf8 b) { return {fn(a.l, b.l), fn(a.h, b.h)}; }
TR_CMP(operator<, _mm_cmplt_ps)
TR_CMP(operator<=, _mm_cmple_ps)
TR_CMP(operator>, _mm_cmpgt_ps)
TR_CMP(operator>=, _mm_cmpge_ps)
TR_CMP(operator==, _mm_cmpeq_ps)
#undef TR_CMP
TR_INLINE vm8 operator&(vm8 a, vm8 b) { return {_mm_and_ps(a.l, b.l), _mm_and_ps(a.h, b.h)}; }
TR_INLINE vm8 operator|(vm8 a, vm8 b) { return {_mm_or_ps(a.l, b.l), _mm_or_ps(a.h, b.h)}; }
TR_INLINE vm8 andnot(vm8 a, vm8 b) { return {_mm_andnot_ps(a.l, b.l), _mm_andnot_ps(a.h, b.h)}; }
TR_INLINE int movemask(vm8 a) { return _mm_movemask_ps(a.l) | (_mm_movemask_ps(a.h) << 4); }
TR_INLINE vm8 as_mask(vf8 a) { return {a.l, a.h}; }  // the sign bits are the mask
TR_INLINE vm8 not_mask(vm8 a) {
    const __m128 ones = _mm_castsi128_ps(_mm_set1_epi32(-1));
    return {_mm_xor_ps(a.l, ones), _mm_xor_ps(a.h, ones)};
}
TR_INLINE vm8 mask_from_bits(int bits) {
    const __m128i lo = _mm_setr_epi32(1, 2, 4, 8), hi = _mm_setr_epi32(16, 32, 64, 128);
    const __m128i b = _mm_set1_epi32(bits);
    return {_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, lo), lo)),
            _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, hi), hi))};
}
TR_INLINE vf8 select(vm8 m, vf8 a, vf8 b) {
    return {_mm_blendv_ps(b.l, a.l, m.l), _mm_blendv_ps(b.h, a.h, m.h)};
}
TR_INLINE vi8 loadi8(const std::uint32_t* p) {
    return {_mm_load_si128(reinterpret_cast<const __m128i*>(p)),
            _mm_load_si128(reinterpret_cast<const __m128i*>(p + 4))};
}
TR_INLINE void storei8(std::uint32_t* p, vi8 a) {
    _mm_store_si128(reinterpret_cast<__m128i*>(p), a.l);
    _mm_store_si128(reinterpret_cast<__m128i*>(p + 4), a.h);
}
TR_INLINE vi8 seti1(std::uint32_t v) {
    return {_mm_set1_epi32(static_cast<int>(v)), _mm_set1_epi32(static_cast<int>(v))};
}
TR_INLINE vm8 lt_signed(vi8 a, vi8 b) {
    return {_mm_castsi128_ps(_mm_cmplt_epi32(a.l, b.l)),
            _mm_castsi128_ps(_mm_cmplt_epi32(a.h, b.h))};
}
TR_INLINE vm8 eqi(vi8 a, vi8 b) {
    return {_mm_castsi128_ps(_mm_cmpeq_epi32(a.l, b.l)),
            _mm_castsi128_ps(_mm_cmpeq_epi32(a.h, b.h))};
}
TR_INLINE vi8 selecti(vm8 m, vi8 a, vi8 b) {
    return {_mm_castps_si128(_mm_blendv_ps(_mm_castsi128_ps(b.l), _mm_castsi128_ps(a.l), m.l)),
            _mm_castps_si128(_mm_blendv_ps(_mm_castsi128_ps(b.h), _mm_castsi128_ps(a.h), m.h))};
}
TR_INLINE float hmin(vf8 a) {
    __m128 m = _mm_min_ps(a.l, a.h);
    m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    m = _mm_min_ss(m, _mm_movehdup_ps(m));
    return _mm_cvtss_f32(m);
}
TR_INLINE float hmax(vf8 a) {
    __m128 m = _mm_max_ps(a.l, a.h);
    m = _mm_max_ps(m, _mm_movehl_ps(m, m));
    m = _mm_max_ss(m, _mm_movehdup_ps(m));
    return _mm_cvtss_f32(m);
}

#endif

// 4 lanes (SSE; VEX-encoded in the AVX2 build), for single blocks of 4 triangles.
struct vf4 {
    __m128 m;
};
struct vm4 {
    __m128 m;
};
TR_INLINE vf4 load4(const float* p) { return {_mm_load_ps(p)}; }
TR_INLINE vf4 set1_4(float f) { return {_mm_set1_ps(f)}; }
TR_INLINE void store4(float* p, vf4 a) { _mm_store_ps(p, a.m); }
TR_INLINE vf4 operator+(vf4 a, vf4 b) { return {_mm_add_ps(a.m, b.m)}; }
TR_INLINE vf4 operator-(vf4 a, vf4 b) { return {_mm_sub_ps(a.m, b.m)}; }
TR_INLINE vf4 operator*(vf4 a, vf4 b) { return {_mm_mul_ps(a.m, b.m)}; }
TR_INLINE vf4 operator/(vf4 a, vf4 b) { return {_mm_div_ps(a.m, b.m)}; }
TR_INLINE vm4 operator<(vf4 a, vf4 b) { return {_mm_cmplt_ps(a.m, b.m)}; }
TR_INLINE vm4 operator<=(vf4 a, vf4 b) { return {_mm_cmple_ps(a.m, b.m)}; }
TR_INLINE vm4 operator>(vf4 a, vf4 b) { return {_mm_cmpgt_ps(a.m, b.m)}; }
TR_INLINE vm4 operator>=(vf4 a, vf4 b) { return {_mm_cmpge_ps(a.m, b.m)}; }
TR_INLINE vm4 operator==(vf4 a, vf4 b) { return {_mm_cmpeq_ps(a.m, b.m)}; }
TR_INLINE vm4 operator&(vm4 a, vm4 b) { return {_mm_and_ps(a.m, b.m)}; }
TR_INLINE vm4 operator|(vm4 a, vm4 b) { return {_mm_or_ps(a.m, b.m)}; }
TR_INLINE vm4 andnot(vm4 a, vm4 b) { return {_mm_andnot_ps(a.m, b.m)}; }
TR_INLINE int movemask(vm4 a) { return _mm_movemask_ps(a.m); }
TR_INLINE vm4 as_mask(vf4 a) { return {a.m}; }
TR_INLINE vm4 not_mask(vm4 a) { return {_mm_xor_ps(a.m, _mm_castsi128_ps(_mm_set1_epi32(-1)))}; }

template <class V>
TR_INLINE V splat(float f);
template <>
TR_INLINE vf8 splat<vf8>(float f) {
    return set1(f);
}
template <>
TR_INLINE vf4 splat<vf4>(float f) {
    return set1_4(f);
}
