#include "engine/gpu/visibility_pass.h"

#include <algorithm>
#include <array>
#include <cstring>

#include "engine/gpu/gpu_error.h"
#include "engine/gpu/gpu_rt_scene.h"
#include "engine/gpu/shader_compiler.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/jobs/parallel_for.h"
#include "view_shadows_shared.h"
#include "visibility_shared.h"

namespace engine::gpu {
namespace {

constexpr VkFormat kVisibilityFormat = VK_FORMAT_R32G32_UINT;  // instance + 1, triangle
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr std::uint32_t kSceneBindings = 8;  // rt_traversal.glsl's
constexpr VkShaderStageFlags kRasterStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

VkShaderModule make_module(VkDevice device, const std::vector<std::uint32_t>& spirv) {
  VkShaderModuleCreateInfo smi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smi.codeSize = spirv.size() * sizeof(std::uint32_t);
  smi.pCode = spirv.data();
  VkShaderModule m = VK_NULL_HANDLE;
  ENGINE_VK_CHECK(vkCreateShaderModule(device, &smi, nullptr, &m));
  return m;
}

VkRenderPass make_render_pass(VkDevice device) {
  std::array<VkAttachmentDescription, 2> a{};
  a[0].format = kVisibilityFormat;
  a[0].samples = VK_SAMPLE_COUNT_1_BIT;
  a[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  a[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  a[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  a[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  a[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  a[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;  // copied into the resolve's buffer
  a[1] = a[0];
  a[1].format = kDepthFormat;
  a[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  a[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  const VkAttachmentReference colour{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  const VkAttachmentReference depth{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &colour;
  sub.pDepthStencilAttachment = &depth;
  // The previous frame's copy out of the target ends before this clear;
  // this frame's writes end before its copy (the render pass's final layout
  // transition, then the barrier in record()).
  VkSubpassDependency before{};
  before.srcSubpass = VK_SUBPASS_EXTERNAL;
  before.dstSubpass = 0;
  before.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  before.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  before.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
  before.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  VkSubpassDependency after{};
  after.srcSubpass = 0;
  after.dstSubpass = VK_SUBPASS_EXTERNAL;
  after.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  after.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  after.dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  after.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  const std::array<VkSubpassDependency, 2> deps{before, after};
  VkRenderPassCreateInfo rci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rci.attachmentCount = static_cast<std::uint32_t>(a.size());
  rci.pAttachments = a.data();
  rci.subpassCount = 1;
  rci.pSubpasses = &sub;
  rci.dependencyCount = static_cast<std::uint32_t>(deps.size());
  rci.pDependencies = deps.data();
  VkRenderPass pass = VK_NULL_HANDLE;
  ENGINE_VK_CHECK(vkCreateRenderPass(device, &rci, nullptr, &pass));
  return pass;
}

// Triangle lists, no vertex input, no culling (the ray tracer sees both
// sides), a reversed depth test (greater is nearer), the viewport and
// scissor set at record time.
VkPipeline make_raster_pipeline(VkDevice device, VkPipelineLayout layout, VkRenderPass pass, VkShaderModule vertex,
                                VkShaderModule fragment) {
  std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
  stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vertex;
  stages[0].pName = "main";
  stages[1] = stages[0];
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fragment;
  VkPipelineVertexInputStateCreateInfo input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = VK_TRUE;
  depth.depthWriteEnable = VK_TRUE;
  depth.depthCompareOp = VK_COMPARE_OP_GREATER;
  VkPipelineColorBlendAttachmentState blend_attachment{};
  blend_attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT;
  VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = 1;
  blend.pAttachments = &blend_attachment;
  const std::array<VkDynamicState, 2> dynamic_states{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dynamic.dynamicStateCount = static_cast<std::uint32_t>(dynamic_states.size());
  dynamic.pDynamicStates = dynamic_states.data();
  VkGraphicsPipelineCreateInfo gpi{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gpi.stageCount = static_cast<std::uint32_t>(stages.size());
  gpi.pStages = stages.data();
  gpi.pVertexInputState = &input;
  gpi.pInputAssemblyState = &assembly;
  gpi.pViewportState = &viewport;
  gpi.pRasterizationState = &raster;
  gpi.pMultisampleState = &multisample;
  gpi.pDepthStencilState = &depth;
  gpi.pColorBlendState = &blend;
  gpi.pDynamicState = &dynamic;
  gpi.layout = layout;
  gpi.renderPass = pass;
  VkPipeline pipeline = VK_NULL_HANDLE;
  ENGINE_VK_CHECK(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &gpi, nullptr, &pipeline));
  return pipeline;
}

}  // namespace

bool VisibilityPass::supported(const VulkanContext& ctx, std::string* why) {
  if (ctx.info().graphics_queue) return true;
  if (why) *why = "the Vulkan queue the engine runs on (family " + std::to_string(ctx.queue_family()) + ") has no graphics";
  return false;
}

VisibilityPass::VisibilityPass(VulkanContext& ctx) : ctx_(ctx), push_(sizeof(VisibilityPushGpu)) {
  std::string why;
  if (!supported(ctx, &why)) throw GpuError("VisibilityPass: " + why);
  const VkDevice d = ctx.device();
  const auto dir = engine_shader_dir();
  const ShaderCompileOptions options = engine_shader_options();  // no RT_RAY_QUERY: the passes read buffers only
  vertex_ = make_module(d, compile_shader(dir / "visibility.vert", options));
  fragment_ = make_module(d, compile_shader(dir / "visibility.frag", options));

  std::array<VkDescriptorSetLayoutBinding, kSceneBindings> b{};
  for (std::uint32_t i = 0; i < kSceneBindings; ++i) b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kRasterStages, nullptr};
  VkDescriptorSetLayoutCreateInfo dli{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dli.bindingCount = kSceneBindings;
  dli.pBindings = b.data();
  ENGINE_VK_CHECK(vkCreateDescriptorSetLayout(d, &dli, nullptr, &set_layout_));
  const VkPushConstantRange range{kRasterStages, 0, sizeof(VisibilityPushGpu)};
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &set_layout_;
  pli.pushConstantRangeCount = 1;
  pli.pPushConstantRanges = &range;
  ENGINE_VK_CHECK(vkCreatePipelineLayout(d, &pli, nullptr, &layout_));
  render_pass_ = make_render_pass(d);
  pipeline_ = make_raster_pipeline(d, layout_, render_pass_, vertex_, fragment_);
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kSceneBindings};
  VkDescriptorPoolCreateInfo dpi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpi.maxSets = 1;
  dpi.poolSizeCount = 1;
  dpi.pPoolSizes = &size;
  ENGINE_VK_CHECK(vkCreateDescriptorPool(d, &dpi, nullptr, &pool_));
  VkDescriptorSetAllocateInfo dai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dai.descriptorPool = pool_;
  dai.descriptorSetCount = 1;
  dai.pSetLayouts = &set_layout_;
  ENGINE_VK_CHECK(vkAllocateDescriptorSets(d, &dai, &set_));

  resolve_ = std::make_unique<ComputePipeline>(ctx, compile_shader(dir / "visibility_resolve.comp", options), 2 + kSceneBindings,
                                               static_cast<std::uint32_t>(sizeof(VisibilityPushGpu)));
}

VisibilityPass::~VisibilityPass() {
  ctx_.forget_deferred(this);
  const VkDevice d = ctx_.device();
  destroy_targets();
  if (pool_) vkDestroyDescriptorPool(d, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(d, pipeline_, nullptr);
  if (render_pass_) vkDestroyRenderPass(d, render_pass_, nullptr);
  if (layout_) vkDestroyPipelineLayout(d, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(d, set_layout_, nullptr);
  if (vertex_) vkDestroyShaderModule(d, vertex_, nullptr);
  if (fragment_) vkDestroyShaderModule(d, fragment_, nullptr);
}

void VisibilityPass::destroy_targets() {
  if (framebuffer_) vkDestroyFramebuffer(ctx_.device(), framebuffer_, nullptr);
  framebuffer_ = VK_NULL_HANDLE;
  visibility_image_ = DeviceImage();
  depth_image_ = DeviceImage();
  width_ = height_ = 0;
}

void VisibilityPass::make_targets(std::uint32_t width, std::uint32_t height) {
  destroy_targets();
  visibility_image_ = DeviceImage(ctx_, width, height, kVisibilityFormat,
                                  VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
  depth_image_ = DeviceImage(ctx_, width, height, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
  const std::array<VkImageView, 2> views{visibility_image_.view(), depth_image_.view()};
  VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fci.renderPass = render_pass_;
  fci.attachmentCount = static_cast<std::uint32_t>(views.size());
  fci.pAttachments = views.data();
  fci.width = width;
  fci.height = height;
  fci.layers = 1;
  ENGINE_VK_CHECK(vkCreateFramebuffer(ctx_.device(), &fci, nullptr, &framebuffer_));
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  visibility_ = GpuBuffer(ctx_, pixels * 2 * sizeof(std::uint32_t), GpuBuffer::Placement::DeviceOnly);
  hits_ = GpuBuffer(ctx_, pixels * sizeof(VisibilityHitGpu));
  resolve_->bind(0, visibility_);
  resolve_->bind(1, hits_);
  if (shadows_) {
    shadows_->bind(0, visibility_);
    shadows_->bind(1, hits_);
  }
  width_ = width;
  height_ = height;
}

void VisibilityPass::prepare(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane) {
  if (camera.width() <= 0 || camera.height() <= 0)
    throw GpuError("VisibilityPass: an image of " + std::to_string(camera.width()) + " x " + std::to_string(camera.height()));
  if (!(near_plane > 0)) throw GpuError("VisibilityPass: the near plane must be positive");
  const auto w = static_cast<std::uint32_t>(camera.width()), h = static_cast<std::uint32_t>(camera.height());
  if (w != width_ || h != height_) make_targets(w, h);
  const GpuRtRasterView view = scene.raster_view();
  std::array<VkDescriptorBufferInfo, kSceneBindings> infos{};
  std::array<VkWriteDescriptorSet, kSceneBindings> writes{};
  for (std::uint32_t i = 0; i < kSceneBindings; ++i) {
    infos[i] = {view.buffers[i]->handle(), 0, VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set_;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
    resolve_->bind(2 + i, *view.buffers[i]);
  }
  vkUpdateDescriptorSets(ctx_.device(), kSceneBindings, writes.data(), 0, nullptr);
  scene_ = &scene;

  push_ = push_for(camera, sample, near_plane);
  shadow_push_.clear();
  // The answers of the view taken before are overwritten by this one's.
  taken_shadows_.reset();
}

void VisibilityPass::prepare_shadows(const GpuRtScene& scene, const render::ViewShadowRequest& request) {
  if (!shadows_) {
    ShaderCompileOptions options = engine_shader_options();
    options.defines = GpuRtScene::shader_defines(ctx_);
    constexpr std::uint32_t kFirstSceneBinding = 4;
    shadows_ = std::make_unique<ComputePipeline>(ctx_, compile_shader(engine_shader_dir() / "view_shadows.comp", options),
                                                 GpuRtScene::binding_types(ctx_, kFirstSceneBinding, kFirstSceneBinding + GpuRtScene::kBindings),
                                                 static_cast<std::uint32_t>(sizeof(VisibilityPushGpu) + sizeof(ViewShadowPushGpu)));
    shadows_->bind(0, visibility_);
    shadows_->bind(1, hits_);
  }
  const std::size_t lights = request.lights.size(), pixels = static_cast<std::size_t>(width_) * height_;
  bind_at_least(ctx_, *shadows_, 2, shadow_lights_, lights * sizeof(ViewShadowLightGpu));
  bind_at_least(ctx_, *shadows_, 3, shadow_answers_, lights * pixels * sizeof(float));
  scene.bind(*shadows_, 4);
  const std::span<ViewShadowLightGpu> out = shadow_lights_.mapped_as<ViewShadowLightGpu>(lights);
  for (std::size_t l = 0; l < lights; ++l) {
    const render::ViewShadowLight& light = request.lights[l];
    ViewShadowLightGpu& g = out[l];
    g.position_x = light.position.x;
    g.position_y = light.position.y;
    g.position_z = light.position.z;
    g.flags = (light.directional ? kViewShadowDirectional : 0u) | (light.nearest ? kViewShadowNearest : 0u);
    for (std::uint32_t c = 0; c < kViewShadowCells; ++c) {
      const glm::vec3 d = light.directional ? light.directions[c] : glm::vec3(0.0f);
      g.directions[4 * c] = d.x;
      g.directions[4 * c + 1] = d.y;
      g.directions[4 * c + 2] = d.z;
      g.directions[4 * c + 3] = 0.0f;
    }
  }
  const ViewShadowPushGpu extra{request.pattern_shift.x, request.pattern_shift.y, static_cast<std::uint32_t>(lights),
                                request.offset_scale};
  shadow_push_ = push_;
  shadow_push_.resize(push_.size() + sizeof(extra));
  std::memcpy(shadow_push_.data() + push_.size(), &extra, sizeof(extra));
}

std::vector<std::uint8_t> VisibilityPass::push_for(const render::CameraRays& camera, glm::vec2 sample, float near_plane) {
  const auto w = static_cast<std::uint32_t>(camera.width()), h = static_cast<std::uint32_t>(camera.height());
  // generate()'s rotation is the camera's to_world rotation.
  const glm::mat3 r = glm::mat3_cast(camera.to_world().rotation);
  const glm::vec3 o = camera.position();
  VisibilityPushGpu p{o.x, o.y, o.z, near_plane, r[0].x, r[0].y, r[0].z, camera.tan_half_x(), r[1].x, r[1].y, r[1].z,
                      camera.tan_half_y(), r[2].x, r[2].y, r[2].z, 0.0f, sample.x, sample.y, w, h};
  std::vector<std::uint8_t> bytes(sizeof(p));
  std::memcpy(bytes.data(), &p, sizeof(p));
  return bytes;
}

void VisibilityPass::queue(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane,
                           const render::ViewShadowRequest* shadows) {
  drop_queued();
  prepare(scene, camera, sample, near_plane);
  if (shadows && !shadows->lights.empty()) {
    prepare_shadows(scene, *shadows);
    queued_shadows_ = *shadows;
  }
  queued_scene_ = &scene;
  queued_push_ = push_;
  ctx_.record_before_next(this, [this](VkCommandBuffer cmd) { record(cmd); });
}

void VisibilityPass::drop_queued() {
  ctx_.forget_deferred(this);
  queued_scene_ = nullptr;
  queued_shadows_.reset();
}

bool VisibilityPass::take_shadows(const render::ViewShadowRequest& request, std::vector<float>& answers) {
  const bool match = taken_shadows_ && *taken_shadows_ == request;
  taken_shadows_.reset();
  if (!match) return false;
  // Read here, not when the view was taken: answers nobody asks for stay on
  // the device. The buffer holds them until the next view is prepared.
  const std::span<const float> out =
      shadow_answers_.mapped_as<const float>(request.lights.size() * static_cast<std::size_t>(width_) * height_);
  answers.assign(out.begin(), out.end());
  return true;
}

bool VisibilityPass::take_queued(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane,
                                 std::span<rt::Hit> hits, std::span<std::uint8_t> found, double* gpu_ms) {
  const bool match = queued_scene_ == &scene && queued_push_ == push_for(camera, sample, near_plane);
  if (!match) {
    drop_queued();
    return false;
  }
  const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
  if (hits.size() != pixels || found.size() != pixels)
    throw GpuError("VisibilityPass::take_queued: " + std::to_string(pixels) + " pixels, " + std::to_string(hits.size()) +
                   " hits, " + std::to_string(found.size()) + " flags");
  if (ctx_.has_deferred(this)) ctx_.flush();
  queued_scene_ = nullptr;
  const double ms = ctx_.take_deferred_ms(this);
  if (gpu_ms) *gpu_ms = ms;
  read_hits(scene, hits, found);
  taken_shadows_ = std::move(queued_shadows_);
  queued_shadows_.reset();
  return true;
}

void VisibilityPass::record(VkCommandBuffer cmd) const {
  if (!scene_) throw GpuError("VisibilityPass::record before prepare");
  std::array<VkClearValue, 2> clear{};
  clear[0].color.uint32[0] = 0;  // no instance
  clear[1].depthStencil = {0.0f, 0};  // reversed: 0 is the far plane
  VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rbi.renderPass = render_pass_;
  rbi.framebuffer = framebuffer_;
  rbi.renderArea = {{0, 0}, {width_, height_}};
  rbi.clearValueCount = static_cast<std::uint32_t>(clear.size());
  rbi.pClearValues = clear.data();
  vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &set_, 0, nullptr);
  vkCmdPushConstants(cmd, layout_, kRasterStages, 0, sizeof(VisibilityPushGpu), push_.data());
  const VkViewport viewport{0.0f, 0.0f, static_cast<float>(width_), static_cast<float>(height_), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {width_, height_}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
  for (const GpuRtRasterView::Draw& draw : scene_->raster_view().draws)
    vkCmdDraw(cmd, 3 * draw.triangles, 1, 3 * draw.first_triangle, draw.instance);
  vkCmdEndRenderPass(cmd);

  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {width_, height_, 1};
  vkCmdCopyImageToBuffer(cmd, visibility_image_.image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, visibility_.handle(), 1, &copy);
  record_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_SHADER_READ_BIT);
  const std::uint32_t pixels = width_ * height_;
  resolve_->record_dispatch(cmd, (pixels + kVisibilityGroupSize - 1) / kVisibilityGroupSize, 1, 1, push_.data());
  if (shadow_push_.empty()) return;
  record_compute_barrier(cmd);
  shadows_->record_dispatch(cmd, (pixels + kVisibilityGroupSize - 1) / kVisibilityGroupSize, 1, 1, shadow_push_.data());
}

void VisibilityPass::render(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane,
                            std::span<rt::Hit> hits, std::span<std::uint8_t> found, double* gpu_ms) {
  const std::size_t pixels = static_cast<std::size_t>(camera.width()) * static_cast<std::size_t>(std::max(camera.height(), 0));
  if (hits.size() != pixels || found.size() != pixels)
    throw GpuError("VisibilityPass::render: " + std::to_string(pixels) + " pixels, " + std::to_string(hits.size()) + " hits, " +
                   std::to_string(found.size()) + " flags");
  drop_queued();  // its bindings and targets are rewritten here
  prepare(scene, camera, sample, near_plane);
  const double ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record(cmd); });
  if (gpu_ms) *gpu_ms = ms;
  read_hits(scene, hits, found);
}

void VisibilityPass::read_hits(const GpuRtScene& scene, std::span<rt::Hit> hits, std::span<std::uint8_t> found) const {
  const std::size_t pixels = hits.size();
  const std::span<const VisibilityHitGpu> out = hits_.mapped_as<const VisibilityHitGpu>(pixels);
  // In parallel, as GpuRtScene::intersect reads its hits: at 1080p a serial
  // pass over 2 M pixels costs more than the raster.
  jobs::parallel_for<std::size_t>(0, pixels, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const VisibilityHitGpu& h = out[i];
      found[i] = h.instance != kRtNoHit ? 1 : 0;
      if (!found[i]) continue;
      const rt::InstanceRecord* record = scene.instance_record(h.instance);
      hits[i].entity = record ? record->entity : ecs::Entity{};
      hits[i].instance = h.instance;
      hits[i].mesh = record ? record->mesh : 0;
      hits[i].primitive = h.primitive;
      hits[i].barycentric = {h.u, h.v};
      hits[i].t = h.t;
    }
  });
}

}  // namespace engine::gpu
