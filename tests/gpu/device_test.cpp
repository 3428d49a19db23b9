// The generic Vulkan pieces: device choice (no driver needed), shader
// compile errors, buffers.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/device_choice.h"
#include "engine/gpu/gpu_acceleration_structures.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/gpu_error.h"
#include "engine/gpu/gpu_rt_scene.h"
#include "engine/gpu/shader_compiler.h"
#include "engine/gpu/vulkan_context.h"
#include "gpu_fixture.h"

using namespace engine::gpu;

TEST(GpuDeviceChoice, ADiscreteGpuBeatsIntegratedAndLavapipeWhateverTheOrder) {
  const std::vector<DeviceCandidate> devices = {
      {"llvmpipe (LLVM 15.0.6, 256 bits)", DeviceKind::Cpu}, {"Intel UHD 770", DeviceKind::Integrated},
      {"NVIDIA H100", DeviceKind::Discrete}};
  const DeviceChoice c = choose_device(devices, "");
  ASSERT_TRUE(c.index) << c.why;
  EXPECT_EQ(*c.index, 2u) << "expected the discrete GPU, got " << devices[*c.index].name;
}

TEST(GpuDeviceChoice, ANamedDeviceWinsOverTheRankCaseInsensitively) {
  const std::vector<DeviceCandidate> devices = {{"NVIDIA H100", DeviceKind::Discrete},
                                                {"llvmpipe (LLVM 15.0.6, 256 bits)", DeviceKind::Cpu}};
  const DeviceChoice c = choose_device(devices, "LLVMpipe");
  ASSERT_TRUE(c.index) << c.why;
  EXPECT_EQ(*c.index, 1u);
}

TEST(GpuDeviceChoice, AnUnmatchedNameIsAnErrorListingTheDevices) {
  const std::vector<DeviceCandidate> devices = {{"llvmpipe", DeviceKind::Cpu}};
  const DeviceChoice c = choose_device(devices, "radeon");
  EXPECT_FALSE(c.index);
  EXPECT_NE(c.why.find("radeon"), std::string::npos) << c.why;
  EXPECT_NE(c.why.find("'llvmpipe'"), std::string::npos) << c.why;
}

TEST(GpuDeviceChoice, ADeviceWithoutAComputeQueueIsPassedOver) {
  const std::vector<DeviceCandidate> devices = {{"display only", DeviceKind::Discrete, false},
                                                {"llvmpipe", DeviceKind::Cpu, true}};
  const DeviceChoice c = choose_device(devices, "");
  ASSERT_TRUE(c.index) << c.why;
  EXPECT_EQ(*c.index, 1u);
  EXPECT_FALSE(choose_device({}, "").index);
}

// A discrete GPU's memory as NVIDIA's driver lays it out: device-local;
// host, uncached (write-combined); host, cached; device-local mapped through
// the BAR. No driver needed.
TEST(GpuBufferMemory, EachPreferenceRanksADiscreteGpusTypesAsItsCommentSays) {
  VkPhysicalDeviceMemoryProperties mem{};
  mem.memoryTypeCount = 4;
  constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  constexpr VkMemoryPropertyFlags kMapped = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  mem.memoryTypes[0].propertyFlags = kLocal;
  mem.memoryTypes[1].propertyFlags = kMapped;
  mem.memoryTypes[2].propertyFlags = kMapped | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  mem.memoryTypes[3].propertyFlags = kLocal | kMapped;
  using V = std::vector<std::uint32_t>;
  EXPECT_EQ(rank_buffer_memory_types(mem, 0xf, true, BufferMemory::Cached), (V{2, 1, 3}));
  EXPECT_EQ(rank_buffer_memory_types(mem, 0xf, true, BufferMemory::WriteCombined), (V{1, 3, 2}));
  EXPECT_EQ(rank_buffer_memory_types(mem, 0xf, true, BufferMemory::Bar), (V{3, 1, 2}));
  EXPECT_EQ(rank_buffer_memory_types(mem, 0xf, false, BufferMemory::Cached), (V{0, 3, 1, 2}))
      << "device-only buffers: unmappable device memory first, host memory last";
  EXPECT_EQ(rank_buffer_memory_types(mem, 0x6, true, BufferMemory::Bar), (V{1, 2})) << "only the types the buffer allows";
  // lavapipe and integrated GPUs: one type that is everything.
  mem.memoryTypeCount = 1;
  mem.memoryTypes[0].propertyFlags = kLocal | kMapped | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  for (const BufferMemory m : {BufferMemory::Cached, BufferMemory::WriteCombined, BufferMemory::Bar})
    EXPECT_EQ(rank_buffer_memory_types(mem, 0x1, true, m), (V{0}));
  EXPECT_EQ(rank_buffer_memory_types(mem, 0x1, false, BufferMemory::Cached), (V{0}));
}

TEST(ShaderCompiler, AGlslErrorNamesTheFileAndLine) {
  const char* source =
      "#version 460\n"
      "layout(local_size_x = 1) in;\n"
      "void main() {\n"
      "  float x = undeclared_thing;\n"
      "}\n";
  try {
    compile_compute_source(source, "bad.comp");
    FAIL() << "expected a compile error";
  } catch (const GpuError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.comp:4: error:"), std::string::npos) << "expected 'bad.comp:4: error:', got: " << msg;
    EXPECT_NE(msg.find("undeclared_thing"), std::string::npos) << msg;
  }
}

TEST(ShaderCompiler, AnErrorInAnIncludedHeaderNamesTheHeaderAndItsLine) {
  const auto dir = std::filesystem::temp_directory_path() / "engine_gpu_include_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "broken.h") << "// a header\nfloat f() { return not_declared; }\n";
  std::ofstream(dir / "main.comp") << "#version 460\n#extension GL_GOOGLE_include_directive : require\n"
                                      "#include \"broken.h\"\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
  try {
    compile_compute_shader(dir / "main.comp");
    FAIL() << "expected a compile error";
  } catch (const GpuError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("broken.h:2: error:"), std::string::npos) << "expected 'broken.h:2: error:', got: " << msg;
  }
  EXPECT_THROW(compile_compute_shader(dir / "missing.comp"), GpuError);
}

// The stage comes from the extension, as glslang's tools read it: a vertex
// shader's gl_Position is no compute shader's, and an unknown extension is
// refused with the file's name.
TEST(ShaderCompiler, TheStageIsTheFilesExtension) {
  const auto dir = std::filesystem::temp_directory_path() / "engine_gpu_stage_test";
  std::filesystem::create_directories(dir);
  const char* vertex = "#version 460\nvoid main() { gl_Position = vec4(float(gl_VertexIndex), 0.0, 0.0, 1.0); }\n";
  for (const char* name : {"v.vert", "v.comp", "v.glsl"}) std::ofstream(dir / name) << vertex;
  const auto spirv = compile_shader(dir / "v.vert");
  ASSERT_GT(spirv.size(), 5u);
  EXPECT_EQ(spirv[0], 0x07230203u);
  EXPECT_THROW(compile_shader(dir / "v.comp"), GpuError) << "gl_Position is not a compute shader's";
  try {
    compile_shader(dir / "v.glsl");
    FAIL() << "expected an unknown stage";
  } catch (const GpuError& e) {
    EXPECT_NE(std::string(e.what()).find("v.glsl"), std::string::npos) << e.what();
  }
}

TEST(ShaderCompiler, AValidShaderBecomesSpirvWithItsMagicNumber) {
  const auto spirv = compile_compute_source("#version 460\nlayout(local_size_x = 1) in;\nvoid main() {}\n", "ok.comp");
  ASSERT_GT(spirv.size(), 5u);
  EXPECT_EQ(spirv[0], 0x07230203u);
}

TEST(GpuBuffer, RoundTripsBytesAndRefusesAnOversizedUpload) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  GpuBuffer b(*ctx, 16 * sizeof(float));
  std::vector<float> in(16), out(16, -1.0f);
  for (int i = 0; i < 16; ++i) in[static_cast<std::size_t>(i)] = static_cast<float>(i) * 0.5f;
  b.upload(std::span<const float>(in));
  b.download(std::span<float>(out));
  EXPECT_EQ(in, out);
  std::vector<float> big(17);
  EXPECT_THROW(b.upload(std::span<const float>(big)), GpuError);
}

// A discrete GPU's path: device memory the CPU cannot map, written and read
// through staging copies (forced here, since lavapipe maps everything).
TEST(GpuBuffer, ADeviceOnlyBufferRoundTripsThroughStagingCopies) {
  std::string why;
  VulkanContext* ctx = gpu_test::staging_context(&why);
  if (!ctx) GTEST_SKIP() << "no Vulkan device: " << why;
  GpuBuffer b(*ctx, 1000 * sizeof(std::uint32_t), GpuBuffer::Placement::DeviceOnly);
  std::vector<std::uint32_t> in(1000), out(1000, 0u);
  for (std::uint32_t i = 0; i < 1000; ++i) in[i] = i * 2654435761u;
  b.upload(std::span<const std::uint32_t>(in));
  b.download(std::span<std::uint32_t>(out));
  EXPECT_EQ(in, out);
  // A shorter upload changes only its prefix.
  const std::vector<std::uint32_t> head = {7u, 8u, 9u};
  b.upload(std::span<const std::uint32_t>(head));
  b.download(std::span<std::uint32_t>(out));
  EXPECT_EQ(out[0], 7u);
  EXPECT_EQ(out[2], 9u);
  EXPECT_EQ(out[3], in[3]);
  std::vector<std::uint32_t> big(1001);
  EXPECT_THROW(b.upload(std::span<const std::uint32_t>(big)), GpuError);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// The traffic a frame reports is counted where it happens: each submission,
// each upload and download by its bytes (a staging copy is one more
// submission), each mapped span by its size and constness.
TEST(GpuTraffic, CountsSubmissionsUploadsDownloadsAndMappedSpans) {
  std::string why;
  VulkanContext* ctx = gpu_test::staging_context(&why);
  if (!ctx) GTEST_SKIP() << "no Vulkan device: " << why;
  GpuBuffer mapped(*ctx, 64 * sizeof(float));
  GpuBuffer device(*ctx, 100 * sizeof(std::uint32_t), GpuBuffer::Placement::DeviceOnly);
  const GpuTraffic before = ctx->traffic();
  std::vector<float> f(64, 1.0f);
  mapped.upload(std::span<const float>(f));                 // 256 bytes up
  mapped.download(std::span<float>(f).first(10));           // 40 bytes down
  (void)mapped.mapped_as<float>(16);                        // written: 64 bytes up
  (void)mapped.mapped_as<const float>(8);                   // read: 32 bytes down
  std::vector<std::uint32_t> u(100, 3u);
  device.upload(std::span<const std::uint32_t>(u));         // 400 up, one staging submission
  device.download(std::span<std::uint32_t>(u).first(50));   // 200 down, one more
  ctx->submit_and_wait([](VkCommandBuffer) {});             // one more
  const GpuTraffic t = ctx->traffic() - before;
  EXPECT_EQ(t.host_to_device_bytes, 256u + 64u + 400u);
  EXPECT_EQ(t.device_to_host_bytes, 40u + 32u + 200u);
  EXPECT_EQ(t.submissions, 3u);
}

TEST(VulkanContext, SaysWhichDeviceItRunsOnAndWhetherValidationIsOn) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const auto& info = ctx->info();
  std::printf("device: %s (%s), driver %s, float16 %s, shared memory %u bytes, timestamps %s, validation %s\n",
              info.name.c_str(), device_kind_name(info.kind), info.driver.c_str(), info.shader_float16 ? "yes" : "no",
              info.max_shared_memory, info.timestamp_period_ns > 0 ? "yes" : "no",
              ctx->validation_enabled() ? "on" : "off (layer not installed)");
  EXPECT_FALSE(info.name.empty());
  // The kernels stage 16 KB of weights in shared memory; Vulkan guarantees 16 KB.
  EXPECT_GE(info.max_shared_memory, 16384u);
}

// GpuOptions::ray_query = false keeps a device with ray queries on the
// compute traversal; the acceleration structures refuse such a context with
// a reason instead of calling entry points that were never looked up.
TEST(VulkanContext, RayQueriesAreUsedOnlyWhereAskedForAndAvailable) {
  std::string why;
  VulkanContext* compute = gpu_test::context_with(false, false, &why);
  if (!compute) GTEST_SKIP() << "no Vulkan device: " << why;
  EXPECT_FALSE(compute->info().ray_query);
  EXPECT_EQ(compute->acceleration_structures().create, nullptr);
  EXPECT_THROW(GpuAccelerationStructures structures(*compute), GpuError);
  EXPECT_NE(describe(compute->info()).find("rays: compute BVH traversal"), std::string::npos) << describe(compute->info());
  VulkanContext* preferred = gpu_test::context(&why);
  ASSERT_NE(preferred, nullptr);
  std::printf("ray queries: %s\n", preferred->info().ray_query ? "yes" : "no (the device has no VK_KHR_ray_query)");
  if (preferred->info().ray_query) {
    EXPECT_NE(preferred->acceleration_structures().cmd_build, nullptr);
    EXPECT_NE(describe(preferred->info()).find("rays: VK_KHR_ray_query"), std::string::npos) << describe(preferred->info());
  }
}

TEST(VulkanContext, AnUnknownRayQuerySettingIsAnErrorNamingTheVariable) {
  ::setenv("ENGINE_GPU_RAY_QUERY", "maybe", 1);
  std::string why;
  const auto ctx = VulkanContext::create(GpuOptions{}, &why);
  ::unsetenv("ENGINE_GPU_RAY_QUERY");
  if (!ctx && why.find("ENGINE_GPU_RAY_QUERY") == std::string::npos) GTEST_SKIP() << "no Vulkan device: " << why;
  EXPECT_EQ(ctx, nullptr);
  EXPECT_EQ(why, "ENGINE_GPU_RAY_QUERY=maybe: expected on or off");
}

// A binding takes only the descriptor type its pipeline declared: a buffer
// where the kernel expects its acceleration structure is refused by name.
TEST(ComputePipeline, ABufferBoundWhereAnAccelerationStructureIsDeclaredIsRefused) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  if (!ctx->info().ray_query) GTEST_SKIP() << ctx->info().name << " has no VK_KHR_ray_query";
  ShaderCompileOptions options;
  options.include_dirs.push_back(ENGINE_TEST_SHADER_DIR);
  options.defines = GpuRtScene::shader_defines(*ctx);
  ComputePipeline pipeline(*ctx, compile_compute_shader(std::filesystem::path(ENGINE_TEST_SHADER_DIR) / "rt_query.comp", options),
                           GpuRtScene::binding_types(*ctx, 2, 2 + GpuRtScene::kBindings), 8);
  GpuBuffer b(*ctx, 64);
  try {
    pipeline.bind(2, b);
    ADD_FAILURE() << "binding a buffer at the acceleration structure's slot must throw";
  } catch (const GpuError& e) {
    EXPECT_NE(std::string(e.what()).find("binding 2 is of descriptor type"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(pipeline.bind(3, b));
  EXPECT_EQ(ctx->validation_errors(), 0);
}
