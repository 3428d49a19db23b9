// Lua gameplay scripts: every API function, hooks, messages, properties,
// errors, the instruction budget, stale handles, hot reload and the sandbox.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/core/log.h"
#include "engine/input/input_state.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/sun.h"
#include "engine/scene/procedural.h"
#include "engine/scene/scene_assets.h"
#include "engine/script/script_plugin.h"
#include "engine/transform/transform_plugin.h"

using namespace engine;
namespace fs = std::filesystem;
using ecs::Entity;

namespace {

class ScriptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("engine_script_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    script::ScriptSettings s;
    s.root = dir_;
    s.limits.instruction_budget = 200'000;
    s.limits.memory_bytes = std::size_t{32} << 20;
    app_.add_plugin<transform::TransformPlugin>();
    app_.add_plugin<script::ScriptPlugin>(s);
    world().resource<core::Log>().set_echo(false);
  }
  void TearDown() override { fs::remove_all(dir_); }

  ecs::World& world() { return app_.world(); }
  script::ScriptRuntime& runtime() { return world().resource<script::ScriptRuntime>(); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name) << text; }
  Entity spawn_scripted(const std::string& file, const std::string& name = "thing", glm::vec3 at = glm::vec3(0.0f)) {
    const Entity e = world().spawn();
    world().emplace<transform::Transform>(e, transform::Transform::from_translation(at));
    world().emplace<scene::Name>(e, scene::Name{name});
    world().emplace<script::Script>(e, script::Script{file, {}});
    return e;
  }
  // The text of every log entry at `level`, one per line.
  std::string logged(core::LogLevel level) {
    std::string out;
    for (const core::LogEntry& e : world().resource<core::Log>().entries())
      if (e.level == level) out += e.text + "\n";
    return out;
  }
  glm::vec3 position(Entity e) { return world().get<transform::Transform>(e).translation; }

  fs::path dir_;
  app::App app_;
};

TEST_F(ScriptTest, HooksRunInOrderWithSelfAndDelta) {
  write("hooks.lua", R"(
    function init(self) self.calls = "init"; self.t = 0 end
    function update(self, dt) self.calls = self.calls .. ",update"; self.t = self.t + dt
      log.info(self.calls, string.format("%.4f", self.t)) end
    function final(self) log.info("final", self.calls) end)");
  const Entity e = spawn_scripted("hooks.lua");
  app_.update();
  app_.update();
  EXPECT_TRUE(runtime().is_enabled(e));
  world().despawn(e);
  app_.update();
  EXPECT_EQ(runtime().instance_count(), 0u);
  EXPECT_EQ(logged(core::LogLevel::Info), "init,update 0.0167\ninit,update,update 0.0333\nfinal init,update,update\n");
  EXPECT_EQ(logged(core::LogLevel::Error), "");
}

TEST_F(ScriptTest, TransformApiMovesTheEntityAndItsWorldTransformFollows) {
  write("move.lua", R"(
    function init(self)
      local t = self.entity.transform
      t:set_position(1, 2, 3)
      t:translate(0.5, 0, -1)
      local x, y, z = t:get_position()
      log.info(x, y, z)
      t:rotate({0, 1, 0}, math.pi / 2)
      t:set_scale(2)
      log.info(t:get_scale())
    end)");
  const Entity e = spawn_scripted("move.lua");
  app_.update();
  EXPECT_EQ(position(e), glm::vec3(1.5f, 2.0f, 2.0f));
  const glm::quat q = world().get<transform::Transform>(e).rotation;
  const glm::vec3 x_axis = q * glm::vec3(1, 0, 0);  // +X turned a quarter about +Y is -Z
  EXPECT_NEAR(x_axis.z, -1.0f, 1e-6f) << "rotate({0,1,0}, pi/2) sent +X to (" << x_axis.x << "," << x_axis.y << "," << x_axis.z << ")";
  EXPECT_EQ(world().get<transform::WorldTransform>(e).translation, glm::vec3(1.5f, 2.0f, 2.0f));
  EXPECT_EQ(world().get<transform::WorldTransform>(e).scale, 2.0f);
  EXPECT_EQ(logged(core::LogLevel::Info), "1.5 2.0 2.0\n2.0\n");
}

TEST_F(ScriptTest, EulerRotationRoundTrips) {
  write("euler.lua", R"(
    function init(self)
      local t = self.entity.transform
      t:set_rotation({0.1, 0.2, 0.3})
      local x, y, z = t:get_rotation()
      log.info(string.format("%.5f %.5f %.5f", x, y, z))
      t:set_rotation({0, 0, 0}); t:rotate({0, 0.25, 0})
      x, y, z = t:get_rotation()
      log.info(string.format("%.5f %.5f %.5f", x, y, z))
    end)");
  spawn_scripted("euler.lua");
  app_.update();
  EXPECT_EQ(logged(core::LogLevel::Info), "0.10000 0.20000 0.30000\n0.00000 0.25000 0.00000\n");
}

TEST_F(ScriptTest, LightApiChangesTheComponent) {
  write("lamp.lua", R"(
    function init(self)
      local l = self.entity.light
      l:set_intensity(12.5); l:set_color(1, 0.5, 0.25); l:set_range(4)
      log.info(l:get_intensity(), l:is_enabled())
      l:set_enabled(false)
      log.info(l:is_enabled())
    end)");
  const Entity e = spawn_scripted("lamp.lua");
  world().emplace<scene::PunctualLight>(e, scene::PunctualLight{});
  app_.update();
  const auto& l = world().get<scene::PunctualLight>(e);
  EXPECT_EQ(l.intensity, 12.5f);
  EXPECT_EQ(l.color, glm::vec3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(l.range, 4.0f);
  EXPECT_FALSE(l.enabled);
  EXPECT_EQ(logged(core::LogLevel::Info), "12.5 true\nfalse\n");
}

TEST_F(ScriptTest, SceneFindSpawnAndDespawn) {
  write("spawner.lua", R"(
    function init(self)
      local target = scene.find("target")
      log.info(target.name, scene.find("nobody") == nil)
      local copy = scene.spawn("target", {4, 5, 6})
      local x, y, z = copy.transform:get_position()
      log.info(x, y, z, copy.light:get_intensity())
      self.copy = copy
    end
    function update(self, dt)
      if self.copy then
        log.info("despawned", scene.despawn(self.copy), scene.despawn(self.copy), self.copy:alive())
        self.copy = nil
      end
    end)");
  const Entity target = spawn_scripted("none.lua", "target", glm::vec3(1, 1, 1));
  world().remove<script::Script>(target);
  scene::PunctualLight light;
  light.intensity = 7.0f;
  world().emplace<scene::PunctualLight>(target, light);
  spawn_scripted("spawner.lua");
  const std::size_t before = world().entity_count();
  app_.update();
  EXPECT_EQ(world().entity_count(), before) << "the spawned copy was despawned in the same frame";
  EXPECT_EQ(logged(core::LogLevel::Info), "target true\n4.0 5.0 6.0 7.0\ndespawned true false false\n");
}

TEST_F(ScriptTest, SpawnByMeshNameAndRaycastFindsIt) {
  auto& assets = world().insert_resource<scene::SceneAssets>();
  assets.generation = scene::next_scene_generation();
  auto box = std::make_shared<scene::MeshAsset>(scene::make_box(glm::vec3(0.5f)));
  box->name = "crate";
  assets.meshes.push_back(box);
  assets.materials.resize(1);
  app_.add_plugin<rt::RtPlugin>();
  write("caster.lua", R"(
    function init(self) self.crate = scene.spawn("crate", {0, 0, -5}) end
    function update(self, dt)
      local hit = scene.raycast({0, 0, 0}, {0, 0, -1})
      if hit then
        log.info(hit.entity == self.crate, string.format("%.3f %.3f", hit.distance, hit.position.z))
      else
        log.info("miss")
      end
      log.info(scene.raycast({0, 0, 0}, {0, 0, 1}) == nil, scene.raycast({0, 0, 0}, {0, 0, -1}, 2) == nil)
    end)");
  spawn_scripted("caster.lua");
  app_.update();  // spawns; the ray-tracing mirror syncs in PrepareRender
  app_.update();  // now the ray finds the crate's near face at z = -4.5
  EXPECT_EQ(logged(core::LogLevel::Info), "miss\ntrue true\ntrue 4.500 -4.500\ntrue true\n");
}

TEST_F(ScriptTest, InputAndTime) {
  write("input.lua", R"(
    function update(self, dt)
      local mx, my = input.mouse()
      log.info(input.down("W"), input.pressed("E"), input.released("space"), mx, my, time.frame(),
               string.format("%.4f %.4f", time.now(), time.dt()))
    end)");
  spawn_scripted("input.lua");
  auto& in = world().resource<input::InputState>();
  in.set_key("space", true);
  app_.update();
  in.begin_frame();
  in.set_key("W", true);
  in.set_key("E", true);
  in.set_key("space", false);
  in.move_mouse({10, 20});
  app_.update();
  EXPECT_EQ(logged(core::LogLevel::Info),
            "false false false 0.0 0.0 0 0.0000 0.0167\ntrue true true 10.0 20.0 1 0.0167 0.0167\n");
}

TEST_F(ScriptTest, MessagesReachOnMessageWithTheirTable) {
  write("sender.lua", R"(
    function update(self, dt)
      if not self.sent then send(scene.find("receiver"), "open", {by = "key", count = 2}); self.sent = true end
    end)");
  write("receiver.lua", R"(
    function on_message(self, id, msg) log.info("got", id, msg.by, msg.count) end)");
  spawn_scripted("sender.lua", "sender");
  spawn_scripted("receiver.lua", "receiver");
  app_.update();
  app_.update();
  EXPECT_EQ(logged(core::LogLevel::Info), "got open key 2\n");
}

TEST_F(ScriptTest, PropertiesTakeDefaultsOverridesAndInspectorEdits) {
  write("props.lua", R"(
    property("speed", 1.5)
    property("label", "door")
    property("locked", true)
    function update(self, dt) log.info(self.speed, self.label, self.locked) end)");
  const Entity a = spawn_scripted("props.lua", "a");
  const Entity b = spawn_scripted("props.lua", "b");
  world().get_mut<script::Script>(b).overrides["speed"] = 3.0;
  app_.update();
  const auto props = runtime().properties(a);
  ASSERT_EQ(props.size(), 3u);
  EXPECT_EQ(props[0].name, "speed");
  EXPECT_EQ(std::get<double>(props[0].value), 1.5);
  EXPECT_TRUE(runtime().set_property(world(), a, "speed", 2.5));
  EXPECT_FALSE(runtime().set_property(world(), a, "speed", std::string("fast"))) << "a property keeps its type";
  EXPECT_FALSE(runtime().set_property(world(), a, "nope", 1.0));
  app_.update();
  EXPECT_EQ(std::get<double>(world().get<script::Script>(a).overrides.at("speed")), 2.5);
  EXPECT_EQ(logged(core::LogLevel::Info), "1.5 door true\n3.0 door true\n2.5 door true\n3.0 door true\n");
}

TEST_F(ScriptTest, AnErrorDisablesOnlyItsScriptAndLogsATraceback) {
  write("bad.lua", R"(
    local function inner() error("the door is stuck") end
    function update(self, dt) inner() end)");
  write("good.lua", "function update(self, dt) log.info('still running') end");
  const Entity bad = spawn_scripted("bad.lua", "bad");
  const Entity good = spawn_scripted("good.lua", "good");
  app_.update();
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(bad));
  EXPECT_TRUE(runtime().is_enabled(good));
  const std::string errors = logged(core::LogLevel::Error);
  EXPECT_NE(errors.find("bad.lua:2: the door is stuck"), std::string::npos) << errors;
  EXPECT_NE(errors.find("stack traceback"), std::string::npos) << errors;
  EXPECT_NE(errors.find("update()"), std::string::npos) << errors;
  EXPECT_EQ(logged(core::LogLevel::Info), "still running\nstill running\n");
}

TEST_F(ScriptTest, CompileErrorsAndMissingFilesAreReportedNotFatal) {
  write("syntax.lua", "function update(self, dt) if then end");
  const Entity broken = spawn_scripted("syntax.lua");
  const Entity missing = spawn_scripted("missing.lua");
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(broken));
  EXPECT_FALSE(runtime().is_enabled(missing));
  const std::string errors = logged(core::LogLevel::Error);
  EXPECT_NE(errors.find("syntax.lua:1:"), std::string::npos) << errors;
  EXPECT_NE(errors.find("cannot open"), std::string::npos) << errors;
}

TEST_F(ScriptTest, AnEndlessLoopIsStoppedByTheBudget) {
  write("loop.lua", "function update(self, dt) while true do end end");
  write("coloop.lua", "function update(self, dt) coroutine.wrap(function() while true do end end)() end");
  const Entity loop = spawn_scripted("loop.lua");
  const Entity coloop = spawn_scripted("coloop.lua");
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(loop));
  EXPECT_FALSE(runtime().is_enabled(coloop));
  const std::string errors = logged(core::LogLevel::Error);
  EXPECT_NE(errors.find("loop.lua"), std::string::npos) << errors;
  EXPECT_NE(errors.find("coloop.lua"), std::string::npos) << errors;
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n') >= 2, true);
  EXPECT_NE(errors.find("instruction budget exceeded (200000"), std::string::npos) << errors;
}

TEST_F(ScriptTest, MemoryIsCapped) {
  write("hog.lua", "function init(self) local t = {} for i = 1, 1e8 do t[i] = string.rep('x', 64) .. i end end");
  const Entity hog = spawn_scripted("hog.lua");
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(hog));
  const std::string errors = logged(core::LogLevel::Error);
  EXPECT_TRUE(errors.find("not enough memory") != std::string::npos || errors.find("budget") != std::string::npos) << errors;
  EXPECT_LE(runtime().sandbox().memory_used(), std::size_t{32} << 20);
}

// Issue 32: all scripts share one Lua state; a leaking one used to take the
// whole budget, keep it once disabled, and make an innocent script fail
// with "not enough memory", with no file or line.
TEST(ScriptMemory, ALeakingScriptStopsAtItsOwnBudgetAndTheOthersRunOn) {
  const fs::path dir = fs::temp_directory_path() / ("engine_script_memory_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "leak.lua") << "local hoard = {}\n"
                                     "function update(self, dt)\n"
                                     "  for i = 1, 2000 do hoard[#hoard + 1] = {i} end\n"
                                     "end\n";
  std::ofstream(dir / "steady.lua") << "function update(self, dt)\n"
                                       "  local t = {}\n"
                                       "  for i = 1, 5000 do t[i] = {i} end\n"
                                       "  self.count = #t\n"
                                       "end\n";
  script::ScriptSettings settings;
  settings.root = dir;
  settings.limits.memory_bytes = std::size_t{8} << 20;
  settings.limits.owner_memory_bytes = std::size_t{2} << 20;
  app::App app;
  app.add_plugin<transform::TransformPlugin>();
  app.add_plugin<script::ScriptPlugin>(settings);
  ecs::World& world = app.world();
  world.resource<core::Log>().set_echo(false);
  Entity leak{}, steady{};
  for (auto [e, file] : {std::pair{&leak, "leak.lua"}, std::pair{&steady, "steady.lua"}}) {
    *e = world.spawn();
    world.emplace<transform::Transform>(*e);
    world.emplace<script::Script>(*e, script::Script{file, {}});
  }
  auto& runtime = world.resource<script::ScriptRuntime>();
  for (int f = 0; f < 60; ++f) app.update();
  std::string errors;
  for (const core::LogEntry& e : world.resource<core::Log>().entries())
    errors += std::string(core::log_level_name(e.level)) + " " + e.source + ": " + e.text + "\n";
  EXPECT_FALSE(runtime.is_enabled(leak)) << errors;
  EXPECT_TRUE(runtime.is_enabled(steady)) << "the leak must not take the other script down:\n" << errors;
  EXPECT_NE(errors.find("leak.lua:3: memory budget exceeded"), std::string::npos) << "the error names the file and line:\n" << errors;
  EXPECT_EQ(errors.find("steady.lua"), std::string::npos) << errors;
  EXPECT_LT(runtime.sandbox().memory_used(), std::size_t{1} << 20)
      << "the disabled script's hoard (2 MB) is freed; what is left is the engine's and the steady script's";
  fs::remove_all(dir);
}

TEST_F(ScriptTest, AStaleHandleIsALuaErrorNotACrash) {
  write("stale.lua", R"(
    function init(self) self.other = scene.find("other") end
    function update(self, dt) self.other.transform:set_position(1, 2, 3) end)");
  const Entity other = spawn_scripted("none.lua", "other");
  world().remove<script::Script>(other);
  const Entity e = spawn_scripted("stale.lua");
  app_.update();
  EXPECT_TRUE(runtime().is_enabled(e));
  world().despawn(other);
  const Entity reused = world().spawn();  // may take the same slot: the generation tells them apart
  world().emplace<transform::Transform>(reused);
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(e));
  EXPECT_EQ(world().get<transform::Transform>(reused).translation, glm::vec3(0.0f));
  const std::string errors = logged(core::LogLevel::Error);
  EXPECT_NE(errors.find("was despawned; its handle is stale"), std::string::npos) << errors;
}

TEST_F(ScriptTest, NonFiniteValuesAreRefused) {
  write("nan.lua", "function init(self) self.entity.transform:set_position(0/0, 0, 0) end");
  const Entity e = spawn_scripted("nan.lua", "n", glm::vec3(1, 2, 3));
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(e));
  EXPECT_EQ(position(e), glm::vec3(1, 2, 3));
  EXPECT_NE(logged(core::LogLevel::Error).find("x must be a finite number"), std::string::npos);
}

TEST_F(ScriptTest, HotReloadKeepsSelfAndCallsOnReload) {
  write("live.lua", R"(
    function init(self) self.count = 0 end
    function update(self, dt) self.count = self.count + 1 end)");
  const Entity e = spawn_scripted("live.lua");
  app_.update();
  app_.update();
  write("live.lua", R"(
    function on_reload(self) log.info("reloaded with count", self.count) end
    function update(self, dt) self.count = self.count + 100 end)");
  // File times can be coarse: move the time forward so the change is seen.
  fs::last_write_time(dir_ / "live.lua", fs::last_write_time(dir_ / "live.lua") + std::chrono::seconds(2));
  app_.update();
  EXPECT_TRUE(runtime().is_enabled(e));
  const std::string info = logged(core::LogLevel::Info);
  EXPECT_NE(info.find("reloaded with count 2"), std::string::npos) << info;
  // A broken edit stops the script; fixing it starts it again.
  write("live.lua", "function update(self, dt) oops( end");
  fs::last_write_time(dir_ / "live.lua", fs::last_write_time(dir_ / "live.lua") + std::chrono::seconds(4));
  app_.update();
  EXPECT_FALSE(runtime().is_enabled(e));
  write("live.lua", "function update(self, dt) log.info('count', self.count) end");
  fs::last_write_time(dir_ / "live.lua", fs::last_write_time(dir_ / "live.lua") + std::chrono::seconds(6));
  app_.update();
  EXPECT_TRUE(runtime().is_enabled(e));
  EXPECT_NE(logged(core::LogLevel::Info).find("count 102"), std::string::npos) << logged(core::LogLevel::Info);
}

TEST_F(ScriptTest, SandboxEscapesAreRefused) {
  const std::vector<std::pair<std::string, std::string>> escapes = {
      {"io", "io.open('/etc/passwd')"},
      {"os", "os.execute('echo escaped')"},
      {"load", "load('return 1')()"},
      {"loadstring", "loadstring('return 1')()"},
      {"dofile", "dofile('/etc/passwd')"},
      {"require", "require('os')"},
      {"dump", "local f = string.dump(function() end); load(f)()"},
      {"debug", "debug.getregistry()"},
      {"package", "package.loadlib('libc.so.6', 'system')"},
  };
  std::vector<Entity> entities;
  for (const auto& [name, code] : escapes) {
    write(name + ".lua", "function init(self) " + code + " end");
    entities.push_back(spawn_scripted(name + ".lua", name));
  }
  app_.update();
  for (std::size_t i = 0; i < escapes.size(); ++i) EXPECT_FALSE(runtime().is_enabled(entities[i])) << escapes[i].second;
  const std::string errors = logged(core::LogLevel::Error);
  EXPECT_NE(errors.find("attempt to index a nil value (global 'io')"), std::string::npos) << errors;
  EXPECT_NE(errors.find("attempt to call a nil value (field 'dump')"), std::string::npos) << errors;
}

TEST(LuaSandbox, BinaryChunksAreRefused) {
  script::LuaSandbox sandbox;
  sandbox.push_new_env();
  const std::string bytecode = std::string("\x1bLua\x54\x00", 6) + "garbage";
  const std::string message = sandbox.load(bytecode, "evil", -1);
  EXPECT_NE(message.find("attempt to load a binary chunk"), std::string::npos) << message;
}

}  // namespace

namespace {

TEST_F(ScriptTest, SkyTurnsTheEnvironmentAndBumpsItsVersion) {
  auto& assets = world().insert_resource<scene::SceneAssets>();
  image::ImageRGB map(8, 4);
  map.at(2, 1) = glm::vec3(100.0f);  // one bright texel: a sun
  assets.environment = scene::Environment(map, 1.0f, glm::mat4(1.0f));
  const glm::vec3 sun_local = scene::Environment::uv_to_direction({2.5f / 8, 1.5f / 4});
  write("sky.lua", R"(
    function init(self) sky.set_yaw(math.pi / 2); sky.set_strength(0.5); log.info(sky.get_yaw() > 1.57, sky.get_strength()) end)");
  spawn_scripted("sky.lua");
  app_.update();
  EXPECT_EQ(assets.edit_version, 2u);
  EXPECT_EQ(logged(core::LogLevel::Info), "true 0.5\n");
  // The sun's texel now shines from its direction turned a quarter about +Y.
  const glm::vec3 turned(sun_local.z, sun_local.y, -sun_local.x);
  EXPECT_NEAR(assets.environment->radiance(turned).x, 50.0f, 1e-3f);
  EXPECT_NEAR(assets.environment->to_world(sun_local).x, turned.x, 1e-5f);
}

}  // namespace

namespace {

TEST_F(ScriptTest, SunSetTurnsTheDirectionalLightAndGetReadsItBack) {
  const ecs::Entity sun = world().spawn();
  world().emplace<transform::Transform>(sun);
  world().emplace<scene::PunctualLight>(sun, scene::PunctualLight{.type = scene::PunctualLight::Type::Directional});
  write("sun.lua", R"(
    function init(self) sun.set(30, 120); local e, a = sun.get(); log.info(math.floor(e + 0.5), math.floor(a + 0.5)) end)");
  spawn_scripted("sun.lua");
  app_.update();
  EXPECT_EQ(logged(core::LogLevel::Info), "30 120\n");
  const glm::vec3 travel = world().get<transform::Transform>(sun).rotation * glm::vec3(0, 0, -1);
  EXPECT_NEAR(glm::dot(travel, -scene::direction_to_sun(30, 120)), 1.0f, 1e-5f);
}

TEST_F(ScriptTest, WorldPositionForwardAndLogLevels) {
  write("world.lua", R"(
    function update(self, dt)
      local x, y, z = self.entity.transform:get_world_position()
      local fx, fy, fz = self.entity.transform:get_forward()
      local function r(v) return math.floor(v * 1000 + 0.5) / 1000 end  -- no "-0.000" from rounding noise
      log.info(string.format("%.3f %.3f %.3f  %.3f %.3f %.3f", r(x), r(y), r(z), r(fx), r(fy), r(fz)))
      log.warn("careful")
      log.error("bad", 42)
      print("printed")
    end)");
  const Entity parent = world().spawn();
  transform::Transform pt = transform::Transform::from_translation({10, 0, 0});
  pt.rotation = glm::angleAxis(3.14159265f / 2, glm::vec3(0, 1, 0));  // local -Z turns to world -X
  world().emplace<transform::Transform>(parent, pt);
  const Entity child = spawn_scripted("world.lua", "child", glm::vec3(0, 0, -2));
  world().emplace<transform::Parent>(child, transform::Parent{parent});
  app_.update();  // the WorldTransform is written in PostUpdate, after the scripts
  world().resource<core::Log>().clear();
  app_.update();
  // The child 2 m down its parent's -Z: the parent faces world -X from x = 10.
  EXPECT_EQ(logged(core::LogLevel::Info), "8.000 0.000 0.000  -1.000 0.000 0.000\nprinted\n");
  EXPECT_EQ(logged(core::LogLevel::Warning), "careful\n");
  EXPECT_EQ(logged(core::LogLevel::Error), "bad 42\n");
  const auto& entries = world().resource<core::Log>().entries();
  ASSERT_FALSE(entries.empty());
  EXPECT_NE(entries.front().source.find("world.lua:"), std::string::npos) << "the source names the file and line";
}

}  // namespace
