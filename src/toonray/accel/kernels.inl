// The traversal kernels (internal to the accel module), written once against the vf8/vm8/vi8
// types of simd8.inl and compiled three times: kernels_sse.cpp (the portable build, 8-wide as
// pairs of SSE registers), kernels_avx2.cpp and kernels_avx512.cpp (ISA options from CMake,
// chosen at run time when the CPU has them). Included inside an anonymous namespace in
// `toonray::accel::<isa>`, after simd8.inl, with all headers already included.
//
// Exactness: every lane of the triangle tests does the float operations of watertight_test()
// in its order (no FMA: the translation units turn contraction off); lanes whose edge
// functions hit an exact zero (which the scalar test redoes in double) are handed to
// watertight_test() itself. A hit is taken by BestHit's rule, with its t held to its
// triangle's box as watertight_test() holds it (held_to_box), so the result is the lowest
// (t, triangle index) over the triangles whose test passes, which does not depend on traversal
// order. occluded1 stops at any lane that BestHit would take as a first hit (0 < t < tmax), so
// it answers exactly whether intersect1 finds one. Box culling is conservative: the far
// distance is widened by kBoxSlack as before; the AVX2/AVX-512 single-ray box test uses FMA
// with its rounding error folded into the constants; interval (frustum) tests bound the per-ray
// two-rounding slab distances exactly (float multiplication is monotonic); and NaN distances
// never cull. A hit whose rounding puts it on a ray that one of these tests finds missing its
// triangle's box is refused on every path (held_to_box in watertight.h), so the box tests cull
// no hit that another path would take.

constexpr int kNearLo[3] = {0, 8, 16};    // offsets of lo[axis] in a WideNode, in floats
constexpr int kNearHi[3] = {24, 32, 40};  // offsets of hi[axis]

template <class V, class M>
struct LaneResultT {
    M ok;    // hit with 0 < t <= tmax (and no exact zero edge function), t not yet held to the
             // triangle's box (held_to_box): a lane that is not ok fails the scalar test, one
             // that is may still fail it
    M zero;  // an edge function is exactly zero: redo in scalar
    V t, u, v;
};
using LaneResult = LaneResultT<vf8, vm8>;

// The first half of watertight_test() on 4 or 8 lanes: the sheared corners and the edge
// functions, from the corners relative to the ray origin (a = v0 - origin etc., components in
// the ray's kx, ky, kz order). `live` has the lanes the sign test does not reject, and those
// with an exact zero (which the scalar test re-evaluates in double before its sign test).
template <class V, class M>
struct EdgesT {
    V e0, e1, e2;
    M zero, live;
};
using Edges = EdgesT<vf8, vm8>;

template <class V, class M>
TR_INLINE EdgesT<V, M> edges(V akx, V aky, V akz, V bkx, V bky, V bkz, V ckx, V cky, V ckz, V sx,
                             V sy) {
    const V zero = splat<V>(0.0f);
    const V ax = akx - sx * akz, ay = aky - sy * akz;
    const V bx = bkx - sx * bkz, by = bky - sy * bkz;
    const V cx = ckx - sx * ckz, cy = cky - sy * ckz;
    EdgesT<V, M> e;
    e.e0 = cx * by - cy * bx;
    e.e1 = ax * cy - ay * cx;
    e.e2 = bx * ay - by * ax;
    e.zero = (e.e0 == zero) | (e.e1 == zero) | (e.e2 == zero);
    // The scalar test rejects when some edge function is < 0 and another > 0. Without zeros
    // that is "the sign bits differ"; lanes with a zero go to the scalar test whatever their
    // signs, and NaN lanes fail the final t test however they are classified here.
    const M s0 = as_mask(e.e0), s1 = as_mask(e.e1), s2 = as_mask(e.e2);
    e.live = (s0 & s1 & s2) | not_mask(s0 | s1 | s2) | e.zero;
    return e;
}
TR_INLINE Edges edges8(vf8 akx, vf8 aky, vf8 akz, vf8 bkx, vf8 bky, vf8 bkz, vf8 ckx, vf8 cky,
                       vf8 ckz, vf8 sx, vf8 sy) {
    return edges<vf8, vm8>(akx, aky, akz, bkx, bky, bkz, ckx, cky, ckz, sx, sy);
}

// The rest of watertight_test(), for lanes the edges leave live.
template <class V, class M>
TR_INLINE LaneResultT<V, M> finish(const EdgesT<V, M>& e, V akz, V bkz, V ckz, V sz, V tmax) {
    const V zero = splat<V>(0.0f);
    const V det = e.e0 + e.e1 + e.e2;
    const V az = sz * akz, bz = sz * bkz, cz = sz * ckz;
    const V st = e.e0 * az + e.e1 * bz + e.e2 * cz;
    const V inv = splat<V>(1.0f) / det;
    const V t = st * inv;
    const M ok = andnot(e.zero | (det == zero), (t > zero) & (t <= tmax) & e.live);
    return {ok, e.zero, t, e.e1 * inv, e.e2 * inv};
}
TR_INLINE LaneResult finish8(const Edges& e, vf8 akz, vf8 bkz, vf8 ckz, vf8 sz, vf8 tmax) {
    return finish<vf8, vm8>(e, akz, bkz, ckz, sz, tmax);
}

inline float as_float(std::uint32_t u) {
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}
inline std::uint32_t as_bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

// ---------------------------------------------------------------------------------------------
// One ray: 8 child boxes per step, leaf blocks two at a time (8 triangles).

// What the single-ray leaf test needs of the ray, computed once per ray.
struct LeafRay {
    ShearedRay sr;
    int ox, oy, oz;  // offsets of the kx, ky, kz rows in a TriBlock corner, in floats
    float o[3];      // origin[kx], origin[ky], origin[kz]
};

// Lane i's t of a window held to its triangle's box (held_to_box in watertight.h).
TR_INLINE float lane_held_to_box(float t, const LeafRay& lr, const TriBlock& b0, const TriBlock& b1,
                                 int i) {
    const TriBlock& b = i < 4 ? b0 : b1;
    const int l = i & 3;
    const int k[3] = {lr.sr.kx, lr.sr.ky, lr.sr.kz};
    float q[3][3];
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) q[c][r] = b.v[c][k[r]][l];
    const float inv[3] = {lr.sr.ix, lr.sr.iy, lr.sr.sz};
    return held_to_box(t, q, lr.o, inv);
}

constexpr std::uint32_t kPrimMask = ~kLeafEnd;

// The scalar test for lanes with an exact zero edge function.
TR_INLINE void leaf_zero_lanes(int zero, const TriBlock& b0, const TriBlock& b1,
                               const ShearedRay& sr, BestHit& best) {
    while (zero) {
        int i = __builtin_ctz(static_cast<unsigned>(zero));
        zero &= zero - 1;
        const TriBlock& b = i < 4 ? b0 : b1;
        int l = i & 3;
        const std::uint32_t prim = b.prim[l] & kPrimMask;
        float t, u, v;
        if (watertight_test(sr, Vec3f(b.v[0][0][l], b.v[0][1][l], b.v[0][2][l]),
                            Vec3f(b.v[1][0][l], b.v[1][1][l], b.v[1][2][l]),
                            Vec3f(b.v[2][0][l], b.v[2][1][l], b.v[2][2][l]), best.t, t, u, v) &&
            best.takes(t, prim))
            best.take(t, prim, u, v);
    }
}

// Takes the lanes `ok` that BestHit's rule takes, each with its t held to its box (which only
// raises t: a lane the rule refuses before is refused after).
template <class V, class M>
TR_INLINE void take_lanes(int ok, const LaneResultT<V, M>& r, const TriBlock& b0,
                          const TriBlock& b1, const LeafRay& lr, BestHit& best) {
    alignas(32) float ts[8], us[8], vs[8];
    if constexpr (sizeof(V) == sizeof(vf8)) {
        store8(ts, r.t);
        store8(us, r.u);
        store8(vs, r.v);
    } else {
        store4(ts, r.t);
        store4(us, r.u);
        store4(vs, r.v);
    }
    do {
        int i = __builtin_ctz(static_cast<unsigned>(ok));
        ok &= ok - 1;
        std::uint32_t prim = (i < 4 ? b0.prim[i] : b1.prim[i - 4]) & kPrimMask;
        if (!best.takes(ts[i], prim)) continue;
        const float t = lane_held_to_box(ts[i], lr, b0, b1, i);
        if (best.takes(t, prim)) best.take(t, prim, us[i], vs[i]);
    } while (ok);
}

// Sign bits of the prims of two blocks: which slots end their leaf.
TR_INLINE int leaf_ends(const TriBlock& b0, const TriBlock& b1) {
    return _mm_movemask_ps(_mm_load_ps(reinterpret_cast<const float*>(b0.prim))) |
           (_mm_movemask_ps(_mm_load_ps(reinterpret_cast<const float*>(b1.prim))) << 4);
}

// Tests a leaf's triangles against one ray, up to 8 at a time (4 when they fit one block), each
// with the current `tmax` (read again for every window). `visit(r, valid, b0, b1)` gets each
// window's lane results, `valid` the lanes that are the leaf's, and returns true to stop.
template <class Visit>
TR_INLINE void leaf_windows(const WideBvh& w, std::uint32_t ref, const LeafRay& lr,
                            const float& tmax, Visit&& visit) {
    const std::uint32_t first = leaf_first(ref);
    const TriBlock* blk = &w.blocks[first / 4];
    int start = static_cast<int>(first % 4);
    int left = static_cast<int>(leaf_count(ref));  // 0: a long leaf, ended by kLeafEnd
    const int kx = lr.ox, ky = lr.oy, kz = lr.oz;
    while (true) {
        // A window of up to 8 slots (two blocks) from the leaf's start.
        const TriBlock& b0 = blk[0];
        const TriBlock& b1 = blk[1];
        const int from = 0xff << start;
        int valid;
        bool done;
        if (left) {
            const int n = std::min(left, 8 - start);
            valid = ((1 << n) - 1) << start;
            left -= n;
            done = left == 0;
        } else {
            const int ends = leaf_ends(b0, b1) & from;
            valid = ends ? from & ((2 << __builtin_ctz(static_cast<unsigned>(ends))) - 1) : from;
            done = ends != 0;
        }
        if ((valid & 0xf0) == 0) {
            // Within the first block: 4 lanes.
            const float* v0 = b0.v[0][0];
            const float* v1 = b0.v[1][0];
            const float* v2 = b0.v[2][0];
            const vf4 okx = set1_4(lr.o[0]), oky = set1_4(lr.o[1]), okz = set1_4(lr.o[2]);
            const vf4 akz = load4(v0 + kz) - okz, bkz = load4(v1 + kz) - okz,
                      ckz = load4(v2 + kz) - okz;
            const EdgesT<vf4, vm4> e = edges<vf4, vm4>(
                load4(v0 + kx) - okx, load4(v0 + ky) - oky, akz, load4(v1 + kx) - okx,
                load4(v1 + ky) - oky, bkz, load4(v2 + kx) - okx, load4(v2 + ky) - oky, ckz,
                set1_4(lr.sr.sx), set1_4(lr.sr.sy));
            if (movemask(e.live) & valid &&
                visit(finish<vf4, vm4>(e, akz, bkz, ckz, set1_4(lr.sr.sz), set1_4(tmax)), valid, b0,
                      b0))
                return;
        } else {
            const float* p0 = &b0.v[0][0][0];
            const float* p1 = &b1.v[0][0][0];
            auto ld = [&](int corner, int row) {
                return load4x2(p0 + corner * 12 + row, p1 + corner * 12 + row);
            };
            const vf8 o8[3] = {bcast(&lr.o[0]), bcast(&lr.o[1]), bcast(&lr.o[2])};
            const vf8 s8[3] = {bcast(&lr.sr.sx), bcast(&lr.sr.sy), bcast(&lr.sr.sz)};
            const vf8 akz = ld(0, kz) - o8[2], bkz = ld(1, kz) - o8[2], ckz = ld(2, kz) - o8[2];
            const Edges e = edges8(ld(0, kx) - o8[0], ld(0, ky) - o8[1], akz, ld(1, kx) - o8[0],
                                   ld(1, ky) - o8[1], bkz, ld(2, kx) - o8[0], ld(2, ky) - o8[1],
                                   ckz, s8[0], s8[1]);
            if (movemask(e.live) & valid &&
                visit(finish8(e, akz, bkz, ckz, s8[2], set1(tmax)), valid, b0, b1))
                return;
        }
        if (done) return;
        blk += 2;
        start = 0;
    }
}

// Not inlined: the traversal loop keeps its registers for the node tests.
__attribute__((noinline)) void leaf1(const WideBvh& w, std::uint32_t ref, const LeafRay& lr,
                                     BestHit& best) {
    leaf_windows(w, ref, lr, best.t,
                 [&](const auto& r, int valid, const TriBlock& b0, const TriBlock& b1) {
                     const int ok = movemask(r.ok) & valid;
                     const int zero = movemask(r.zero) & valid;
                     if (ok) take_lanes(ok, r, b0, b1, lr, best);
                     if (zero) leaf_zero_lanes(zero, b0, b1, lr.sr, best);
                     return false;
                 });
}

// Whether a leaf holds a triangle hit with 0 < t < tmax: the lanes that leaf1 would take as a
// first hit (a lane passes the test with t <= tmax, and a first hit must be below tmax).
__attribute__((noinline)) bool leaf_occluded(const WideBvh& w, std::uint32_t ref, const LeafRay& lr,
                                             float tmax) {
    bool hit = false;
    leaf_windows(w, ref, lr, tmax,
                 [&](const auto& r, int valid, const TriBlock& b0, const TriBlock& b1) {
                     int below = movemask(r.ok & (r.t < splat<decltype(r.t)>(tmax))) & valid;
                     if (below) {
                         alignas(32) float ts[8];
                         if constexpr (sizeof(r.t) == sizeof(vf8)) store8(ts, r.t);
                         else store4(ts, r.t);
                         do {
                             const int i = __builtin_ctz(static_cast<unsigned>(below));
                             below &= below - 1;
                             if (lane_held_to_box(ts[i], lr, b0, b1, i) < tmax) return hit = true;
                         } while (below);
                     }
                     int zero = movemask(r.zero) & valid;
                     while (zero) {
                         const int i = __builtin_ctz(static_cast<unsigned>(zero));
                         zero &= zero - 1;
                         const TriBlock& b = i < 4 ? b0 : b1;
                         const int l = i & 3;
                         float t, u, v;
                         if (watertight_test(lr.sr, Vec3f(b.v[0][0][l], b.v[0][1][l], b.v[0][2][l]),
                                             Vec3f(b.v[1][0][l], b.v[1][1][l], b.v[1][2][l]),
                                             Vec3f(b.v[2][0][l], b.v[2][1][l], b.v[2][2][l]), tmax,
                                             t, u, v) &&
                             t < tmax)
                             return hit = true;
                     }
                     return false;
                 });
    return hit;
}

// The shear and corner offsets of a ray, for the leaf tests.
TR_INLINE LeafRay leaf_ray(const Ray& ray) {
    LeafRay lr;
    lr.sr = ShearedRay(ray);
    lr.ox = lr.sr.kx * 4;
    lr.oy = lr.sr.ky * 4;
    lr.oz = lr.sr.kz * 4;
    lr.o[0] = ray.origin[lr.sr.kx];
    lr.o[1] = ray.origin[lr.sr.ky];
    lr.o[2] = ray.origin[lr.sr.kz];
    return lr;
}

// The slab test of one ray against the 8 child boxes of a wide node. Near planes: lo for a
// positive direction, hi for a negative one (by the sign bit, so that -0 picks hi like -inf
// would). (Six scalar offsets rather than a loop over arrays, which GCC would vectorise and
// then unpack at every node.)
struct RayBoxes {
    std::size_t nr[3], fr[3];
#ifdef TOONRAY_ACCEL_FMA
    // Slab distances as one fused multiply-add per plane, t = p * inv + c with c = -o * inv,
    // made conservative in the constants (fused_slab in watertight.h); the far distance is
    // then widened by kBoxSlack as in the plain test. This visits other boxes than the SSE
    // kernels' two-rounding test, but a hit in a box that either test culls is refused on
    // every path (held_to_box), so the hit (lowest t, then index, over the FMA-free triangle
    // tests) is the same: every ISA gives the same pixels (tile_test.cpp,
    // scripts/compare-frames.sh).
    vf8 in8[3], cn8[3], cf8[3];
#else
    vf8 o8[3], i8[3];
#endif

    TR_INLINE explicit RayBoxes(const Ray& ray) {
        const float inv[3] = {1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z};
        const std::size_t nx = as_bits(inv[0]) >> 31, ny = as_bits(inv[1]) >> 31,
                          nz = as_bits(inv[2]) >> 31;
        nr[0] = 0 + 24 * nx;
        nr[1] = 8 + 24 * ny;
        nr[2] = 16 + 24 * nz;
        fr[0] = 24 - 24 * nx;
        fr[1] = 32 - 24 * ny;
        fr[2] = 40 - 24 * nz;
        for (int a = 0; a < 3; ++a) {
#ifdef TOONRAY_ACCEL_FMA
            const FusedSlab slab = fused_slab(ray.origin[a], inv[a]);
            in8[a] = set1(inv[a]);
            cn8[a] = set1(slab.near);
            cf8[a] = set1(slab.far);
#else
            o8[a] = set1(ray.origin[a]);
            i8[a] = set1(inv[a]);
#endif
        }
    }

    // The children the ray may enter before `tmax8` (all lanes tmax), with their entry
    // distances in `tn`. Empty slots have empty boxes, but NaN distances (degenerate rays)
    // cull nothing.
    TR_INLINE unsigned test(const WideNode& node, vf8 tmax8, vf8& tn) const {
        const float* b = &node.lo[0][0];
        const vf8 zero = set1(0.0f);
#ifdef TOONRAY_ACCEL_FMA
        tn = vmax(fmadd(load8(b + nr[0]), in8[0], cn8[0]), zero);
        tn = vmax(fmadd(load8(b + nr[1]), in8[1], cn8[1]), tn);
        tn = vmax(fmadd(load8(b + nr[2]), in8[2], cn8[2]), tn);
        vf8 tf = vmin(fmadd(load8(b + fr[0]), in8[0], cf8[0]), tmax8);
        tf = vmin(fmadd(load8(b + fr[1]), in8[1], cf8[1]), tf);
        tf = vmin(fmadd(load8(b + fr[2]), in8[2], cf8[2]), tf);
#else
        tn = vmax((load8(b + nr[0]) - o8[0]) * i8[0], zero);
        tn = vmax((load8(b + nr[1]) - o8[1]) * i8[1], tn);
        tn = vmax((load8(b + nr[2]) - o8[2]) * i8[2], tn);
        vf8 tf = vmin((load8(b + fr[0]) - o8[0]) * i8[0], tmax8);
        tf = vmin((load8(b + fr[1]) - o8[1]) * i8[1], tf);
        tf = vmin((load8(b + fr[2]) - o8[2]) * i8[2], tf);
#endif
        return static_cast<unsigned>(movemask(tn <= tf * set1(kBoxSlack))) & node.pad[0];
    }
};

TR_INLINE std::uint64_t stack_key(float tnear, std::uint32_t ref) {
    return (static_cast<std::uint64_t>(as_bits(tnear)) << 32) |
           ref;  // tnear >= +0: bits order like floats
}

// Nearest-first traversal of one ray through a wide tree: `leaf(ref)` tests a leaf and returns
// the best distance after it, which culls what is left (boxes entered beyond it cannot hold a
// nearer hit). `t` is the best distance to start from. `stack` holds w.max_stack entries.
template <class Leaf>
TR_INLINE void nearest_loop(const WideBvh& w, const RayBoxes& boxes, float t, Leaf&& leaf,
                            std::uint64_t* stack) {
    if (w.root == kEmptyChild) return;
    float cull = t * kBoxSlack;  // boxes entered beyond this cannot hold a hit
    vf8 tmax8 = set1(t);
    std::uint32_t ref = w.root;
    std::size_t sp = 0;
    while (true) {
        while (!is_leaf(ref)) {
            const WideNode& node = w.nodes[ref];
            vf8 tn;
            unsigned mask = boxes.test(node, tmax8, tn);
            if (mask == 0) goto pop;
            const unsigned first = __builtin_ctz(mask);
            mask &= mask - 1;
            if (mask == 0) {
                ref = node.child[first];
                continue;
            }
            alignas(32) float tns[8];
            store8(tns, tn);
            const unsigned second = __builtin_ctz(mask);
            mask &= mask - 1;
            if (mask == 0) {
                // Two: go to the nearer, keep the farther.
                const bool swap = tns[second] < tns[first];
                const unsigned n = swap ? second : first, f = swap ? first : second;
                stack[sp++] = stack_key(tns[f], node.child[f]);
                ref = node.child[n];
                continue;
            }
            // More: push them all sorted, nearest last, and continue with the nearest.
            const std::size_t base = sp;
            std::uint64_t k0 = stack_key(tns[first], node.child[first]);
            std::uint64_t k1 = stack_key(tns[second], node.child[second]);
            stack[sp++] = k0 > k1 ? k0 : k1;
            stack[sp++] = k0 > k1 ? k1 : k0;
            do {
                const unsigned i = __builtin_ctz(mask);
                mask &= mask - 1;
                const std::uint64_t key = stack_key(tns[i], node.child[i]);
                std::size_t j = sp++;
                while (j > base && stack[j - 1] < key) {
                    stack[j] = stack[j - 1];
                    --j;
                }
                stack[j] = key;
            } while (mask);
            ref = static_cast<std::uint32_t>(stack[--sp]);
        }
        {
            const float after = leaf(ref);
            if (after != t) {
                t = after;
                cull = t * kBoxSlack;
                tmax8 = set1(t);
            }
        }
    pop:
        while (true) {
            if (sp == 0) return;
            const std::uint64_t e = stack[--sp];
            if (as_float(static_cast<std::uint32_t>(e >> 32)) <= cull) {
                ref = static_cast<std::uint32_t>(e);
                break;
            }
        }
    }
}

// The closest hit of one ray by BestHit's rule, starting from `best` (its distance bounds the
// search; its prim decides ties at that distance, see kTieWins).
TR_INLINE void nearest1(const WideBvh& w, const Ray& ray, BestHit& best, std::uint64_t* stack) {
    // The shear is set up at the first leaf: many rays (those that miss) never need it.
    LeafRay lr;
    bool have_lr = false;
    nearest_loop(
        w, RayBoxes(ray), best.t,
        [&](std::uint32_t ref) {
            if (!have_lr) {
                lr = leaf_ray(ray);
                have_lr = true;
            }
            leaf1(w, ref, lr, best);
            return best.t;
        },
        stack);
}

bool intersect1(const WideBvh& w, const Ray& ray, Hit& hit, std::uint64_t* stack) {
    BestHit best{ray.tmax};
    nearest1(w, ray, best, stack);
    if (best.prim == kNoIndex) return false;
    hit.t = best.t;
    hit.prim = best.prim;
    hit.u = best.u;
    hit.v = best.v;
    return true;
}

// Occlusion traversal of one ray: children in slot order (when any hit will do, nearest-first
// costs more than it finds: measured on shadow rays, 2-4% more instructions), stopping when
// `leaf(ref)` returns true.
template <class Leaf>
TR_INLINE bool any_loop(const WideBvh& w, const RayBoxes& boxes, float tmax, Leaf&& leaf,
                        std::uint64_t* stack) {
    if (w.root == kEmptyChild) return false;
    const vf8 tmax8 = set1(tmax);
    std::uint32_t ref = w.root;
    std::size_t sp = 0;
    while (true) {
        while (!is_leaf(ref)) {
            const WideNode& node = w.nodes[ref];
            vf8 tn;
            unsigned mask = boxes.test(node, tmax8, tn);
            if (mask == 0) goto pop;
            ref = node.child[__builtin_ctz(mask)];
            for (mask &= mask - 1; mask; mask &= mask - 1)
                stack[sp++] = node.child[__builtin_ctz(mask)];
        }
        if (leaf(ref)) return true;
    pop:
        if (sp == 0) return false;
        ref = static_cast<std::uint32_t>(stack[--sp]);
    }
}

// Occlusion of one ray: intersect1's traversal with tmax fixed, stopping at the first leaf
// with a hit. `stack` holds WideBvh::max_stack entries.
bool occluded1(const WideBvh& w, const Ray& ray, std::uint64_t* stack) {
    LeafRay lr;
    bool have_lr = false;
    return any_loop(
        w, RayBoxes(ray), ray.tmax,
        [&](std::uint32_t ref) {
            if (!have_lr) {
                lr = leaf_ray(ray);
                have_lr = true;
            }
            return leaf_occluded(w, ref, lr, ray.tmax);
        },
        stack);
}

// ---------------------------------------------------------------------------------------------
// Instances: a top-level tree over instance boxes whose leaves list instance records; each
// record's tree is traversed with the ray taken into its object space. Hit distances are the
// same in both spaces (the direction is transformed with the origin), so the best distance
// carries over from instance to instance. Ties at one distance go to the lower rank (the own
// triangles, then instances by index), then the lower triangle index: the result is the lowest
// (t, rank, triangle) whatever order instances and triangles are visited in.

// The ray in a record's object space: each coordinate summed in double and rounded once, so
// that it is the same on every CPU.
TR_INLINE Ray object_ray(const InstanceRecord& r, const Ray& ray) {
    if (r.identity) return ray;
    const auto& m = r.from_world;
    Ray o;
    for (int i = 0; i < 3; ++i) {
        o.origin[i] =
            static_cast<float>(double(m[i][0]) * ray.origin.x + double(m[i][1]) * ray.origin.y +
                               double(m[i][2]) * ray.origin.z + double(m[i][3]));
        o.dir[i] = static_cast<float>(double(m[i][0]) * ray.dir.x + double(m[i][1]) * ray.dir.y +
                                      double(m[i][2]) * ray.dir.z);
    }
    o.tmax = ray.tmax;
    return o;
}

// A direction in a record's object space, as object_ray transforms it.
TR_INLINE Vec3f object_dir(const InstanceRecord& r, const Vec3f& d) {
    if (r.identity) return d;
    const auto& m = r.from_world;
    Vec3f o;
    for (int i = 0; i < 3; ++i)
        o[i] = static_cast<float>(double(m[i][0]) * d.x + double(m[i][1]) * d.y +
                                  double(m[i][2]) * d.z);
    return o;
}

// The best hit over instances: BestHit plus the rank of the instance hit.
struct RankedHit {
    BestHit hit;
    std::uint32_t rank = 0;

    // The start of a search in a record of rank `rank`: below the best distance, and at the
    // same distance only when its rank is lower than the best hit's.
    [[nodiscard]] BestHit start(std::uint32_t r) const {
        BestHit b{hit.t};
        if (hit.prim != kNoIndex && r < rank) b.prim = kTieWins;
        return b;
    }
    void merge(const BestHit& b, std::uint32_t r) {
        if (b.prim >= kTieWins) return;  // nothing better in that record
        hit = b;
        rank = r;
    }
};

// The records a top-level leaf lists: f(record) for each.
template <class F>
TR_INLINE bool for_each_record(const InstanceLevel& lv, std::uint32_t ref, F&& f) {
    for (std::uint32_t slot = leaf_first(ref);; ++slot) {
        const std::uint32_t s = lv.slots[slot];
        if (f(lv.records[s & kPrimMask])) return true;
        if (s & kLeafEnd) return false;
    }
}

bool intersect1_instances(const InstanceLevel& lv, const Ray& ray, Hit& hit, std::uint64_t* stack,
                          std::uint64_t* bottom) {
    RankedHit best{BestHit{ray.tmax}, 0};
    nearest_loop(
        lv.tree, RayBoxes(ray), ray.tmax,
        [&](std::uint32_t ref) {
            for_each_record(lv, ref, [&](const InstanceRecord& r) {
                BestHit b = best.start(r.rank);
                nearest1(*r.tree, object_ray(r, ray), b, bottom);
                best.merge(b, r.rank);
                return false;
            });
            return best.hit.t;
        },
        stack);
    if (best.hit.prim == kNoIndex) return false;
    hit.t = best.hit.t;
    hit.prim = best.hit.prim;
    hit.u = best.hit.u;
    hit.v = best.hit.v;
    hit.instance = best.rank - 1;  // the own triangles' rank 0 gives kNoIndex
    return true;
}

bool occluded1_instances(const InstanceLevel& lv, const Ray& ray, std::uint64_t* stack,
                         std::uint64_t* bottom) {
    return any_loop(
        lv.tree, RayBoxes(ray), ray.tmax,
        [&](std::uint32_t ref) {
            return for_each_record(lv, ref, [&](const InstanceRecord& r) {
                return occluded1(*r.tree, object_ray(r, ray), bottom);
            });
        },
        stack);
}

// ---------------------------------------------------------------------------------------------
// A tile of up to 16 x 16 rays from one origin, as groups of 4 x 2 rays (one vector each).
// Each group keeps the interval of its rays' inverse directions; a node's children are culled
// for the whole tile at once, then for each group (8 groups per vector), and leaves are tested
// one triangle against a group's 8 rays at a time. Groups whose rays do not share the shear
// permutation, or have a zero or NaN direction component or one whose sign changes, are traced
// ray by ray instead.

constexpr int kMaxGroups = 32;

struct alignas(32) TileState {
    float sx[kMaxGroups][8], sy[kMaxGroups][8], sz[kMaxGroups][8];
    float ix[kMaxGroups][8], iy[kMaxGroups][8];  // 1 / dir[kx], 1 / dir[ky]
    float tmax[kMaxGroups][8], u[kMaxGroups][8], v[kMaxGroups][8];
    std::uint32_t prim[kMaxGroups][8];
    float ilo[3][kMaxGroups], ihi[3][kMaxGroups];  // per group, per axis: range of 1 / dir
    float gtmax[kMaxGroups];                       // largest tmax of the group's rays
    int k[kMaxGroups][3];                          // kx, ky, kz
    int cls[kMaxGroups];                           // the permutation as one number
    int pix[kMaxGroups][8];
    int lanes[kMaxGroups];  // lanes that are real rays (others repeat lane 0)
};

// Lanes with an exact zero edge function go through the scalar test.
TR_INLINE void group_zero_lanes(int zero, TileState& s, int g, const Vec3f& origin,
                                const TriBlock& b, int j, std::uint32_t p) {
    const Vec3f v0(b.v[0][0][j], b.v[0][1][j], b.v[0][2][j]);
    const Vec3f v1(b.v[1][0][j], b.v[1][1][j], b.v[1][2][j]);
    const Vec3f v2(b.v[2][0][j], b.v[2][1][j], b.v[2][2][j]);
    do {
        int i = __builtin_ctz(static_cast<unsigned>(zero));
        zero &= zero - 1;
        ShearedRay sr;
        sr.kx = s.k[g][0];
        sr.ky = s.k[g][1];
        sr.kz = s.k[g][2];
        sr.sx = s.sx[g][i];
        sr.sy = s.sy[g][i];
        sr.sz = s.sz[g][i];
        sr.ix = s.ix[g][i];
        sr.iy = s.iy[g][i];
        sr.origin = origin;
        const BestHit bh{s.tmax[g][i], s.prim[g][i], s.u[g][i], s.v[g][i]};
        float t, u, v;
        if (watertight_test(sr, v0, v1, v2, bh.t, t, u, v) && bh.takes(t, p)) {
            s.tmax[g][i] = t;
            s.prim[g][i] = p;
            s.u[g][i] = u;
            s.v[g][i] = v;
        }
    } while (zero);
}

// held_to_box() of watertight.h for a regular group's 8 lanes: the corners relative to the
// origin `p` shared (those of triangle j of block b, in the group's kx, ky, kz order `k`), the
// inverse directions per lane, with no zero component (finite inverses). The same operations
// lane by lane: a lane's sign bit picks the sides as signbit does, vmin and vmax are lane_min
// and lane_max, multiplying by -1 is negation, and exact_fmadd rounds once as std::fma does.
TR_INLINE vf8 group_held_to_box(vf8 t, const vf8 (&p)[3][3], const vf8 (&inv)[3], const TriBlock& b,
                                int j, const int (&k)[3], const Vec3f& origin) {
    const vf8 zero = set1(0.0f), inf = set1(std::numeric_limits<float>::infinity());
    vf8 entry = zero, exit = inf;
    vm8 culled = zero < zero;
    for (int r = 0; r < 3; ++r) {
        const vf8 lo = vmin(vmin(p[0][r], p[1][r]), p[2][r]);
        const vf8 hi = vmax(vmax(p[0][r], p[1][r]), p[2][r]);
        const vm8 negative = as_mask(inv[r]);
        culled = culled | (negative & (lo > zero)) | andnot(negative, hi < zero);  // behind
        entry = vmax(select(negative, hi, lo) * inv[r], entry);
        exit = vmin(select(negative, lo, hi) * inv[r], exit);
    }
    const vf8 slack = set1(kBoxSlack);
    culled = culled | not_mask(entry <= exit * slack);
    // fused_test_keeps lane by lane; the fused test only where some lane needs it.
    const vm8 kept = (exit >= set1(kVouchedExitMin)) & (exit <= set1(kVouchedExitMax)) &
                     (entry <= exit * set1(kVouchedRoom));
    if (movemask(culled | kept) != 0xff) {
        vf8 fused_entry = zero, fused_exit = inf;
        for (int r = 0; r < 3; ++r) {
            const float q0 = b.v[0][k[r]][j], q1 = b.v[1][k[r]][j], q2 = b.v[2][k[r]][j];
            const vf8 lo = set1(lane_min(lane_min(q0, q1), q2));
            const vf8 hi = set1(lane_max(lane_max(q0, q1), q2));
            const vm8 negative = as_mask(inv[r]);
            const vf8 c = (set1(origin[k[r]]) * inv[r]) * set1(-1.0f);  // fused_slab
            const vf8 margin = vabs(c) * set1(kFusedMargin) + set1(kFusedFloor);
            fused_entry =
                vmax(exact_fmadd(select(negative, hi, lo), inv[r], c - margin), fused_entry);
            fused_exit =
                vmin(exact_fmadd(select(negative, lo, hi), inv[r], c + margin), fused_exit);
        }
        // Only on the lanes the shortcut does not vouch for, as the scalar hold.
        culled = culled | andnot(kept, not_mask(fused_entry <= fused_exit * slack));
    }
    const vf8 bound = entry * set1(kEntrySlack);
    return select(culled, set1(std::numeric_limits<float>::quiet_NaN()),
                  select(t < bound, bound, t));
}

// Tests the rays of `groups` against every triangle of a leaf, triangle by triangle: the
// triangle's corners relative to the origin, in a permutation's order, are shared by all groups
// of that permutation (usually all of them).
TR_INLINE void leaf_groups(const WideBvh& w, std::uint32_t ref, TileState& s, std::uint32_t groups,
                           const Vec3f& origin) {
    const vi8 none = seti1(kNoIndex);
    std::uint32_t touched = 0;
    for (std::uint32_t slot = leaf_first(ref);; ++slot) {
        const TriBlock& b = w.blocks[slot / 4];
        const int j = static_cast<int>(slot % 4);
        const std::uint32_t p = b.prim[j] & kPrimMask;
        const bool last = (b.prim[j] & kLeafEnd) != 0;
        vf8 a[3][3];  // [corner][kx, ky, kz]
        int cls = 0;
        auto prepare = [&](int g) {
            cls = s.cls[g];
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r)
                    a[c][r] = set1(b.v[c][s.k[g][r]][j] - origin[s.k[g][r]]);
        };
        prepare(__builtin_ctz(groups));
        std::uint32_t gm = groups;
        do {
            const int g = __builtin_ctz(gm);
            gm &= gm - 1;
            if (s.cls[g] != cls) prepare(g);
            const Edges e = edges8(a[0][0], a[0][1], a[0][2], a[1][0], a[1][1], a[1][2], a[2][0],
                                   a[2][1], a[2][2], load8(s.sx[g]), load8(s.sy[g]));
            if (!movemask(e.live)) continue;
            const vf8 tmax = load8(s.tmax[g]);
            const LaneResult r = finish8(e, a[0][2], a[1][2], a[2][2], load8(s.sz[g]), tmax);
            const vi8 prim = loadi8(s.prim[g]), pv = seti1(p);
            const vm8 lower = andnot(eqi(prim, none), lt_signed(pv, prim));
            vm8 take = r.ok & ((r.t < tmax) | lower);
            vf8 t = r.t;
            if (movemask(take)) {
                // Held to the triangle's box, a t can only rise or be refused: take again.
                const vf8 inv[3] = {load8(s.ix[g]), load8(s.iy[g]), load8(s.sz[g])};
                t = group_held_to_box(t, a, inv, b, j, s.k[g], origin);
                take = take & (t <= tmax) & ((t < tmax) | lower);
            }
            if (movemask(take)) {
                store8(s.tmax[g], select(take, t, tmax));
                store8(s.u[g], select(take, r.u, load8(s.u[g])));
                store8(s.v[g], select(take, r.v, load8(s.v[g])));
                storei8(s.prim[g], selecti(take, pv, prim));
                touched |= 1u << g;
            }
            if (const int zero = movemask(r.zero)) {
                group_zero_lanes(zero, s, g, origin, b, j, p);
                touched |= 1u << g;
            }
        } while (gm);
        if (last) break;
    }
    while (touched) {
        const int g = __builtin_ctz(touched);
        touched &= touched - 1;
        s.gtmax[g] = hmax(load8(s.tmax[g]));
    }
}

// Which signs the regular groups' directions have, per axis (any lane of any group).
struct TileSigns {
    int pos[3] = {0, 0, 0}, neg[3] = {0, 0, 0};
};

// Leaves every group of `s` empty: no interval bound, nothing to find (gtmax -inf).
TR_INLINE void clear_groups(TileState& s) {
    const float inf = std::numeric_limits<float>::infinity();
    for (int g = 0; g < kMaxGroups; ++g) {
        for (int a = 0; a < 3; ++a) s.ilo[a][g] = s.ihi[a][g] = 1.0f;
        s.gtmax[g] = -inf;
    }
}

// Group g's shear and inverse-direction intervals from its 8 directions d[axis][lane]; false
// when its rays must be traced one by one (no common shear permutation, or a zero, NaN or
// sign-changing direction component).
TR_INLINE bool setup_group(TileState& s, int g, const float (&d)[3][8], TileSigns& signs) {
    const float inf = std::numeric_limits<float>::infinity();
    const vf8 dv[3] = {load8(d[0]), load8(d[1]), load8(d[2])};
    const vf8 adx = vabs(dv[0]), ady = vabs(dv[1]), adz = vabs(dv[2]);
    // kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2), as ShearedRay does per ray.
    const vm8 xy = adx > ady;
    const int m0 = movemask(xy & (adx > adz)), m1 = movemask(andnot(xy, ady > adz));
    int kz = m0 == 0xff ? 0 : m1 == 0xff ? 1 : (m0 | m1) == 0 ? 2 : -1;
    bool ok = kz >= 0;
    vf8 iv[3];
    int neg[3];
    for (int a = 0; a < 3 && ok; ++a) {
        iv[a] = set1(1.0f) / dv[a];
        neg[a] = movemask(iv[a] < set1(0.0f));
        ok = movemask(vabs(iv[a]) < set1(inf)) == 0xff && (neg[a] == 0 || neg[a] == 0xff);
    }
    if (!ok) return false;
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (neg[kz]) std::swap(kx, ky);  // dir[kz] < 0 on every lane
    s.k[g][0] = kx;
    s.k[g][1] = ky;
    s.k[g][2] = kz;
    s.cls[g] = kz * 2 + (neg[kz] ? 1 : 0);
    store8(s.sx[g], dv[kx] / dv[kz]);
    store8(s.sy[g], dv[ky] / dv[kz]);
    store8(s.sz[g], iv[kz]);
    store8(s.ix[g], iv[kx]);
    store8(s.iy[g], iv[ky]);
    for (int a = 0; a < 3; ++a) {
        s.ilo[a][g] = hmin(iv[a]);
        s.ihi[a][g] = hmax(iv[a]);
        (neg[a] ? signs.neg : signs.pos)[a] = 1;
    }
    return true;
}

// Traverses a tile's regular groups through a wide tree, nearest child first, culling for the
// whole tile and then per group; `leaf(ref, groups)` tests a leaf against the groups that
// reach it and updates their lanes' best hits and s.gtmax. `stack` holds w.max_stack entries.
template <class Leaf>
TR_INLINE void tile_loop(const WideBvh& w, TileState& s, int ng, std::uint32_t regular,
                         const TileSigns& signs, const Vec3f& origin, Leaf&& leaf,
                         TileEntry* stack) {
    if (!regular || w.root == kEmptyChild) return;
    const float inf = std::numeric_limits<float>::infinity();
    const int* sign_pos = signs.pos;
    const int* sign_neg = signs.neg;
    // The tile's interval per axis, over its regular groups; an axis on which the groups'
    // signs differ gives no bound ("free").
    float tlo[3] = {inf, inf, inf}, thi[3] = {-inf, -inf, -inf};
    bool free_axis[3];
    int tn_off[3], tf_off[3];
    for (int a = 0; a < 3; ++a) {
        for (int g = 0; g < ng; ++g)
            if (regular >> g & 1) {
                tlo[a] = std::min(tlo[a], s.ilo[a][g]);
                thi[a] = std::max(thi[a], s.ihi[a][g]);
            }
        free_axis[a] = sign_pos[a] && sign_neg[a];
        tn_off[a] = sign_neg[a] ? kNearHi[a] : kNearLo[a];
        tf_off[a] = sign_neg[a] ? kNearLo[a] : kNearHi[a];
    }
    const float o[3] = {origin.x, origin.y, origin.z};
    const vf8 zero = set1(0.0f), slack = set1(kBoxSlack);
    auto tile_tmax = [&] {
        vf8 m = vmax(load8(s.gtmax), load8(s.gtmax + 8));
        m = vmax(m, vmax(load8(s.gtmax + 16), load8(s.gtmax + 24)));
        return hmax(m);
    };
    float ttmax = tile_tmax();

    std::uint32_t ref = w.root, groups = regular;
    std::size_t sp = 0;
    while (true) {
        while (!is_leaf(ref)) {
            const WideNode& n = w.nodes[ref];
            const float* b = &n.lo[0][0];
            // Whole tile against the 8 children.
            vf8 tn = zero, tf = set1(ttmax);
            for (int a = 0; a < 3; ++a) {
                if (free_axis[a]) continue;
                const vf8 lo = set1(tlo[a]), hi = set1(thi[a]), oa = set1(o[a]);
                const vf8 dn = load8(b + tn_off[a]) - oa, df = load8(b + tf_off[a]) - oa;
                tn = vmax(vmin(dn * lo, dn * hi), tn);
                tf = vmin(vmax(df * lo, df * hi), tf);
            }
            int cmask = movemask(tn <= tf * slack) & static_cast<int>(n.pad[0]);
            if (cmask == 0) goto pop;
            alignas(32) float tns[8], dlo[3][8], dhi[3][8];
            store8(tns, tn);
            for (int a = 0; a < 3; ++a) {
                store8(dlo[a], load8(b + kNearLo[a]) - set1(o[a]));
                store8(dhi[a], load8(b + kNearHi[a]) - set1(o[a]));
            }
            // Each child against the groups.
            std::size_t base = sp;
            do {
                int c = __builtin_ctz(static_cast<unsigned>(cmask));
                cmask &= cmask - 1;
                std::uint32_t gm = 0;
                for (int q = 0; q < 4; ++q) {
                    const std::uint32_t qm = (groups >> (8 * q)) & 0xff;
                    if (!qm) continue;
                    vf8 gtn = zero, gtf = load8(s.gtmax + 8 * q);
                    for (int a = 0; a < 3; ++a) {
                        const vf8 il = load8(s.ilo[a] + 8 * q), ih = load8(s.ihi[a] + 8 * q);
                        const vf8 l = bcast(&dlo[a][c]), h = bcast(&dhi[a][c]);
                        if (free_axis[a]) {
                            const vf8 p1 = l * il, p2 = l * ih, p3 = h * il, p4 = h * ih;
                            gtn = vmax(vmin(vmin(p1, p2), vmin(p3, p4)), gtn);
                            gtf = vmin(vmax(vmax(p1, p2), vmax(p3, p4)), gtf);
                        } else {
                            const vf8 nn = sign_neg[a] ? h : l, ff = sign_neg[a] ? l : h;
                            gtn = vmax(vmin(nn * il, nn * ih), gtn);
                            gtf = vmin(vmax(ff * il, ff * ih), gtf);
                        }
                    }
                    gm |= static_cast<std::uint32_t>(movemask(gtn <= gtf * slack) &
                                                     static_cast<int>(qm))
                          << (8 * q);
                }
                if (!gm) continue;
                TileEntry e{n.child[c], gm, tns[c]};
                std::size_t j = sp++;
                while (j > base && stack[j - 1].tnear < e.tnear) {
                    stack[j] = stack[j - 1];
                    --j;
                }
                stack[j] = e;
            } while (cmask);
            if (sp == base) goto pop;
            --sp;
            ref = stack[sp].ref;
            groups = stack[sp].groups;
        }
        leaf(ref, groups);
        ttmax = tile_tmax();
    pop:
        while (true) {
            if (sp == 0) return;
            const TileEntry& e = stack[--sp];
            if (e.tnear <= ttmax * kBoxSlack) {
                ref = e.ref;
                groups = e.groups;
                break;
            }
        }
    }
}

// The groups of a width x height tile (4 x 2 rays each): each lane's pixel and direction, which
// lanes are real rays (the others repeat the group's first), and whether the group is regular.
// Regular groups start with no hit below tmax_in.
TR_INLINE int setup_tile(TileState& s, const Vec3f* dirs, int width, int height, float tmax_in,
                         std::uint32_t& regular, std::uint32_t& irregular, TileSigns& signs) {
    const int gw = (width + 3) / 4, gh = (height + 1) / 2, ng = gw * gh;
    regular = irregular = 0;
    clear_groups(s);
    for (int g = 0; g < ng; ++g) {
        const int gx = (g % gw) * 4, gy = (g / gw) * 2;
        alignas(32) float d[3][8];
        int lanes = 0;
        for (int l = 0; l < 8; ++l) {
            int x = gx + (l & 3), y = gy + (l >> 2);
            if (x < width && y < height) {
                lanes |= 1 << l;
            } else {
                x = gx;
                y = gy;
            }
            const int p = y * width + x;
            s.pix[g][l] = p;
            d[0][l] = dirs[p].x;
            d[1][l] = dirs[p].y;
            d[2][l] = dirs[p].z;
        }
        s.lanes[g] = lanes;
        if (!setup_group(s, g, d, signs)) {
            irregular |= 1u << g;
            continue;
        }
        store8(s.tmax[g], set1(tmax_in));
        store8(s.u[g], set1(0.0f));
        store8(s.v[g], set1(0.0f));
        storei8(s.prim[g], seti1(kNoIndex));
        s.gtmax[g] = tmax_in;
        regular |= 1u << g;
    }
    return ng;
}

void intersect_tile(const WideBvh& w, const Vec3f& origin, const Vec3f* dirs, int width, int height,
                    float tmax_in, Hit* hits, bool* found, TileEntry* stack,
                    std::uint64_t* stack1) {
    TileState s;
    std::uint32_t regular, irregular;
    TileSigns signs;
    const int ng = setup_tile(s, dirs, width, height, tmax_in, regular, irregular, signs);
    tile_loop(
        w, s, ng, regular, signs, origin,
        [&](std::uint32_t ref, std::uint32_t groups) { leaf_groups(w, ref, s, groups, origin); },
        stack);

    // Write the results.
    for (int g = 0; g < ng; ++g) {
        int lanes = s.lanes[g];
        if (irregular >> g & 1) {
            do {
                int l = __builtin_ctz(static_cast<unsigned>(lanes));
                lanes &= lanes - 1;
                const int p = s.pix[g][l];
                hits[p] = Hit{};
                found[p] = intersect1(w, Ray{origin, dirs[p], tmax_in}, hits[p], stack1);
            } while (lanes);
            continue;
        }
        do {
            int l = __builtin_ctz(static_cast<unsigned>(lanes));
            lanes &= lanes - 1;
            const int p = s.pix[g][l];
            const bool f = s.prim[g][l] != kNoIndex;
            found[p] = f;
            hits[p] = f ? Hit{s.tmax[g][l], s.prim[g][l], s.u[g][l], s.v[g][l]} : Hit{};
        } while (lanes);
    }
}

// A tile through the instance level: the top tree is traversed with the tile's groups as
// intersect_tile does; at each record the groups that reach it are taken into its object space
// (each lane's direction, as object_ray does) and traced through its tree with their best hits
// so far, ties going to the lower rank (RankedHit). Groups that are irregular in object space,
// and all of them when they are sparse for the record's tree (WideBvh::dense_for, or an infinite
// `ray_angle2`), are traced there ray by ray.
void intersect_tile_instances(const InstanceLevel& lv, const Vec3f& origin, const Vec3f* dirs,
                              int width, int height, float tmax_in, float ray_angle2, Hit* hits,
                              bool* found, TileEntry* stack, std::uint64_t* stack1,
                              TileEntry* bottom, std::uint64_t* bottom1) {
    TileState s;
    std::uint32_t regular, irregular;
    TileSigns signs;
    const int ng = setup_tile(s, dirs, width, height, tmax_in, regular, irregular, signs);
    // Unless given, the squared angle between the first two rays (the tile's spacing, in any
    // space a similarity takes it to).
    if (ray_angle2 < 0.0f) {
        ray_angle2 = 0.0f;
        if (width * height >= 2) {
            const Vec3f step = normalize(dirs[1]) - normalize(dirs[0]);
            ray_angle2 = dot(step, step);
        }
    }
    alignas(32) std::uint32_t rank[kMaxGroups][8];
    TileState so;  // the groups in a record's object space
    tile_loop(
        lv.tree, s, ng, regular, signs, origin,
        [&](std::uint32_t ref, std::uint32_t groups) {
            for_each_record(lv, ref, [&](const InstanceRecord& r) {
                const Ray oray = object_ray(r, Ray{origin, Vec3f(0.0f), tmax_in});
                const bool sparse =
                    std::isinf(ray_angle2) || !r.tree->dense_for(oray.origin, ray_angle2);
                clear_groups(so);
                TileSigns osigns;
                std::uint32_t oregular = 0;
                std::uint32_t gm = groups;
                do {
                    const int g = __builtin_ctz(gm);
                    gm &= gm - 1;
                    alignas(32) float d[3][8];
                    for (int l = 0; l < 8; ++l) {
                        const Vec3f dir = object_dir(r, dirs[s.pix[g][l]]);
                        d[0][l] = dir.x;
                        d[1][l] = dir.y;
                        d[2][l] = dir.z;
                        so.pix[g][l] = s.pix[g][l];
                        const bool tie = s.prim[g][l] != kNoIndex && r.rank < rank[g][l];
                        so.prim[g][l] = tie ? kTieWins : kNoIndex;
                    }
                    so.lanes[g] = s.lanes[g];
                    if (!sparse && setup_group(so, g, d, osigns)) {
                        store8(so.tmax[g], load8(s.tmax[g]));
                        store8(so.u[g], load8(s.u[g]));
                        store8(so.v[g], load8(s.v[g]));
                        so.gtmax[g] = s.gtmax[g];
                        oregular |= 1u << g;
                        continue;
                    }
                    // Ray by ray.
                    int lanes = s.lanes[g];
                    do {
                        const int l = __builtin_ctz(static_cast<unsigned>(lanes));
                        lanes &= lanes - 1;
                        BestHit b{s.tmax[g][l], so.prim[g][l], s.u[g][l], s.v[g][l]};
                        nearest1(*r.tree, Ray{oray.origin, Vec3f(d[0][l], d[1][l], d[2][l])}, b,
                                 bottom1);
                        if (b.prim >= kTieWins) continue;
                        s.tmax[g][l] = b.t;
                        s.prim[g][l] = b.prim;
                        s.u[g][l] = b.u;
                        s.v[g][l] = b.v;
                        rank[g][l] = r.rank;
                    } while (lanes);
                    // Lanes that are not rays repeat the first (lane 0 always is one).
                    for (int l = 1; l < 8; ++l) {
                        if (s.lanes[g] >> l & 1) continue;
                        s.tmax[g][l] = s.tmax[g][0];
                        s.prim[g][l] = s.prim[g][0];
                        s.u[g][l] = s.u[g][0];
                        s.v[g][l] = s.v[g][0];
                        rank[g][l] = rank[g][0];
                    }
                    s.gtmax[g] = hmax(load8(s.tmax[g]));
                } while (gm);
                tile_loop(
                    *r.tree, so, ng, oregular, osigns, oray.origin,
                    [&](std::uint32_t leaf, std::uint32_t og) {
                        leaf_groups(*r.tree, leaf, so, og, oray.origin);
                    },
                    bottom);
                for (std::uint32_t om = oregular; om;) {
                    const int g = __builtin_ctz(om);
                    om &= om - 1;
                    bool changed = false;
                    for (int l = 0; l < 8; ++l) {
                        if (so.prim[g][l] >= kTieWins) continue;
                        s.tmax[g][l] = so.tmax[g][l];
                        s.prim[g][l] = so.prim[g][l];
                        s.u[g][l] = so.u[g][l];
                        s.v[g][l] = so.v[g][l];
                        rank[g][l] = r.rank;
                        changed = true;
                    }
                    if (changed) s.gtmax[g] = hmax(load8(s.tmax[g]));
                }
                return false;
            });
        },
        stack);

    for (int g = 0; g < ng; ++g) {
        int lanes = s.lanes[g];
        if (irregular >> g & 1) {
            do {
                int l = __builtin_ctz(static_cast<unsigned>(lanes));
                lanes &= lanes - 1;
                const int p = s.pix[g][l];
                hits[p] = Hit{};
                found[p] = intersect1_instances(lv, Ray{origin, dirs[p], tmax_in}, hits[p], stack1,
                                                bottom1);
            } while (lanes);
            continue;
        }
        do {
            int l = __builtin_ctz(static_cast<unsigned>(lanes));
            lanes &= lanes - 1;
            const int p = s.pix[g][l];
            const bool f = s.prim[g][l] != kNoIndex;
            found[p] = f;
            hits[p] =
                f ? Hit{s.tmax[g][l], s.prim[g][l], s.u[g][l], s.v[g][l], rank[g][l] - 1} : Hit{};
        } while (lanes);
    }
}
