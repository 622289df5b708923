#include "embree_reference.h"

#include <stdexcept>

#ifdef TOONRAY_BENCH_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace toonray::bench {

#ifdef TOONRAY_BENCH_HAVE_EMBREE

struct EmbreeScene::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
};

bool EmbreeScene::available() { return true; }

EmbreeScene::EmbreeScene(std::span<const Vec3f> positions,
                         std::span<const std::array<std::uint32_t, 3>> tris)
    : impl_(std::make_unique<Impl>()) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw std::runtime_error("Embree: cannot create a device");
    impl_->scene = rtcNewScene(impl_->device);
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // rtcSetNewGeometryBuffer pads the buffer as Embree's SIMD loads require.
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
    for (std::size_t i = 0; i < positions.size(); ++i) {
        v[3 * i] = positions[i].x;
        v[3 * i + 1] = positions[i].y;
        v[3 * i + 2] = positions[i].z;
    }
    auto* ix = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), tris.size()));
    for (std::size_t i = 0; i < tris.size(); ++i)
        for (int k = 0; k < 3; ++k) ix[3 * i + k] = tris[i][k];
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(impl_->scene);
    if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE)
        throw std::runtime_error("Embree: scene build failed");
}

EmbreeScene::~EmbreeScene() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
}

bool EmbreeScene::intersect(const Ray& ray, Hit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray.org_x = ray.origin.x;
    rh.ray.org_y = ray.origin.y;
    rh.ray.org_z = ray.origin.z;
    rh.ray.dir_x = ray.dir.x;
    rh.ray.dir_y = ray.dir.y;
    rh.ray.dir_z = ray.dir.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = ray.tmax;
    rh.ray.mask = 0xffffffffu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    hit.prim = rh.hit.primID;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    return true;
}

#else

struct EmbreeScene::Impl {};

bool EmbreeScene::available() { return false; }

EmbreeScene::EmbreeScene(std::span<const Vec3f>, std::span<const std::array<std::uint32_t, 3>>) {
    throw std::runtime_error("this benchmark was built without Embree");
}

EmbreeScene::~EmbreeScene() = default;

bool EmbreeScene::intersect(const Ray&, Hit&) const { return false; }

#endif

}  // namespace toonray::bench
