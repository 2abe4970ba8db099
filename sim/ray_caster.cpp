#include "coloc/sim/ray_caster.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <thread>
#include <limits>
#include <string>

#include "coloc/core/error.hpp"

namespace coloc::sim {

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<RTCGeometry> geometries;
  std::vector<std::size_t> triangle_counts;
  bool committed = false;
};

namespace {

void fillBuffers(RTCGeometry geometry, const TriangleMesh& mesh) {
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) std::memcpy(vertices + 3 * i, mesh.vertices[i].data(), 3 * sizeof(float));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = static_cast<unsigned>(mesh.triangles[i][k]);
}

}  // namespace

RayCaster::RayCaster() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw Error("ray casting: Embree could not create a device");
  impl_->scene = rtcNewScene(impl_->device);
}

RayCaster::~RayCaster() {
  if (!impl_) return;
  for (RTCGeometry g : impl_->geometries) rtcReleaseGeometry(g);
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

int RayCaster::addMesh(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) throw Error("ray casting: a mesh without triangles");
  for (const auto& t : mesh.triangles)
    if ((t.array() < 0).any() || (t.array() >= static_cast<int>(mesh.vertices.size())).any())
      throw Error("ray casting: a triangle indexes a vertex that does not exist");
  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  fillBuffers(geometry, mesh);
  rtcCommitGeometry(geometry);
  const unsigned id = rtcAttachGeometry(impl_->scene, geometry);
  if (id != impl_->geometries.size()) throw Error("ray casting: unexpected geometry id");
  impl_->geometries.push_back(geometry);
  impl_->triangle_counts.push_back(mesh.triangles.size());
  impl_->committed = false;
  return static_cast<int>(id);
}

void RayCaster::updateMesh(int id, const TriangleMesh& mesh) {
  if (id < 0 || static_cast<std::size_t>(id) >= impl_->geometries.size() || impl_->triangle_counts[id] != mesh.triangles.size())
    throw Error("ray casting: mesh " + std::to_string(id) + " cannot be updated with a different mesh");
  RTCGeometry geometry = impl_->geometries[id];
  auto* vertices = static_cast<float*>(rtcGetGeometryBufferData(geometry, RTC_BUFFER_TYPE_VERTEX, 0));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) std::memcpy(vertices + 3 * i, mesh.vertices[i].data(), 3 * sizeof(float));
  rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(geometry);
  impl_->committed = false;
}

void RayCaster::commit() {
  rtcCommitScene(impl_->scene);
  impl_->committed = true;
}

namespace {

void checkCast(bool committed, std::size_t origins, std::size_t directions) {
  if (!committed) throw Error("ray casting: commit() the scene before casting");
  if (origins != directions) throw Error("ray casting: origins and directions differ in number");
}

// Rays [from, to) in packets of 8; a short last packet has its unused lanes masked off.
void castPackets(RTCScene scene, const std::vector<Eigen::Vector3f>& origins, const std::vector<Eigen::Vector3f>& directions, float max_range,
                 std::vector<RayHit>& hits, std::size_t from, std::size_t to) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  for (std::size_t i = from; i < to; i += 8) {
    const std::size_t n = std::min<std::size_t>(8, to - i);
    alignas(32) int valid[8];
    RTCRayHit8 rh;
    for (std::size_t k = 0; k < 8; ++k) {
      const std::size_t r = i + std::min(k, n - 1);  // unused lanes repeat the last ray, masked off
      valid[k] = k < n ? -1 : 0;
      rh.ray.org_x[k] = origins[r].x();
      rh.ray.org_y[k] = origins[r].y();
      rh.ray.org_z[k] = origins[r].z();
      rh.ray.dir_x[k] = directions[r].x();
      rh.ray.dir_y[k] = directions[r].y();
      rh.ray.dir_z[k] = directions[r].z();
      rh.ray.tnear[k] = 0.0f;
      rh.ray.tfar[k] = max_range;
      rh.ray.time[k] = 0.0f;
      rh.ray.mask[k] = std::numeric_limits<unsigned>::max();
      rh.ray.id[k] = 0;
      rh.ray.flags[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene, &context, &rh);
    for (std::size_t k = 0; k < n; ++k)
      if (rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID) hits[i + k] = {rh.ray.tfar[k], static_cast<int>(rh.hit.geomID[k])};
  }
}

}  // namespace

void RayCaster::cast(const std::vector<Eigen::Vector3f>& origins, const std::vector<Eigen::Vector3f>& directions, float max_range,
                     std::vector<RayHit>& hits) const {
  checkCast(impl_->committed, origins.size(), directions.size());
  hits.assign(origins.size(), RayHit{});
  // One contiguous share per core (neighbouring rays stay together in packets); a few rays are not
  // worth a thread.
  const std::size_t threads = origins.size() < 4096 ? 1 : std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  const std::size_t share = (origins.size() / threads + 7) / 8 * 8;
  std::vector<std::size_t> bounds(threads + 1, origins.size());
  for (std::size_t t = 0; t < threads; ++t) bounds[t] = std::min(origins.size(), t * share);
  std::vector<std::thread> workers;
  for (std::size_t t = 1; t < threads; ++t)
    workers.emplace_back(castPackets, impl_->scene, std::cref(origins), std::cref(directions), max_range, std::ref(hits), bounds[t], bounds[t + 1]);
  castPackets(impl_->scene, origins, directions, max_range, hits, bounds[0], bounds[1]);
  for (std::thread& w : workers) w.join();
}

void RayCaster::castOneByOne(const std::vector<Eigen::Vector3f>& origins, const std::vector<Eigen::Vector3f>& directions, float max_range,
                             std::vector<RayHit>& hits) const {
  checkCast(impl_->committed, origins.size(), directions.size());
  hits.assign(origins.size(), RayHit{});
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (std::size_t i = 0; i < origins.size(); ++i) {
    RTCRayHit rh{};
    rh.ray.org_x = origins[i].x();
    rh.ray.org_y = origins[i].y();
    rh.ray.org_z = origins[i].z();
    rh.ray.dir_x = directions[i].x();
    rh.ray.dir_y = directions[i].y();
    rh.ray.dir_z = directions[i].z();
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = max_range;
    rh.ray.mask = std::numeric_limits<unsigned>::max();
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &context, &rh);
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) hits[i] = {rh.ray.tfar, static_cast<int>(rh.hit.geomID)};
  }
}

std::size_t RayCaster::triangleCount() const {
  std::size_t n = 0;
  for (std::size_t c : impl_->triangle_counts) n += c;
  return n;
}

}  // namespace coloc::sim
