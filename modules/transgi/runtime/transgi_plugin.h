#pragma once
// TransGI as an engine plugin. Add it, give mesh entities a LatentMesh
// (attach_latent_meshes does it for a whole loaded scene), spawn a
// ProbeVolume, set GiFrame's size, and each App::update() renders GI; a
// moved entity updates it by itself, because the Embree mirror, the light
// set and the probes all follow its WorldTransform.
//
// Systems, in the order each phase runs them, and what holds after them:
//  PrepareRender  transgi::sync_probe_volumes: every ProbeVolume has a probe
//                 field for the current settings and bounds; fields whose
//                 scene changed this frame (geometry or lights) were told,
//                 so settled probes wake and moved geometry is reclassified;
//                 each field's viewer (its visibility test's view bias) is
//                 the camera.
//  Render         transgi::queue_camera_view: on a device that rasterises,
//                 the real-time path's camera view (with this frame's
//                 jitter) is queued to be drawn with the next submission.
//                 transgi::update_probes: probes traced, shared, accumulated
//                 and projected for this frame.
//                 transgi::render_gi: if GiFrame has a size, its gi / direct
//                 / full images and stage times are this frame's.
#include <memory>

#include "engine/app/app.h"
#include "runtime/components.h"
#include "runtime/gi_frame.h"
#include "runtime/settings.h"

namespace engine::gpu {
class VulkanContext;
}

namespace transgi::runtime {

class TransGIPlugin final : public engine::app::Plugin {
 public:
  explicit TransGIPlugin(TransGISettings settings = {}) : settings_(std::move(settings)) {}
  // With Backend::Vulkan, the kernels run on `host_gpu` (a context on the
  // host engine's own device: engine::gpu::VulkanContext::adopt) instead of
  // a device of their own; settings.gpu_device is then ignored.
  TransGIPlugin(TransGISettings settings, std::shared_ptr<engine::gpu::VulkanContext> host_gpu)
      : settings_(std::move(settings)), host_gpu_(std::move(host_gpu)) {}
  void build(engine::app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "transgi::TransGIPlugin"; }

 private:
  TransGISettings settings_;
  std::shared_ptr<engine::gpu::VulkanContext> host_gpu_;
};

// Gives every entity whose MeshInstance has latents in `model` a LatentMesh.
// The model must have been baked for this scene (validate_model). Returns
// how many entities got one.
std::size_t attach_latent_meshes(engine::ecs::World& world, const std::shared_ptr<const model::TransferModel>& model);

}  // namespace transgi::runtime
