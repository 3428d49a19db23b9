#pragma once
// Lua gameplay scripts as an engine plugin. Adds the ScriptRuntime, Log and
// InputState resources and one system:
//  Update  script::run_scripts: every Script component's hooks ran for this
//          frame (see ScriptRuntime); Transforms and lights they changed are
//          marked changed, so PostUpdate and the renderers follow.
#include "engine/app/app.h"
#include "engine/script/script_runtime.h"

namespace engine::script {

class ScriptPlugin final : public app::Plugin {
 public:
  explicit ScriptPlugin(ScriptSettings settings = {}) : settings_(std::move(settings)) {}
  void build(app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "engine::ScriptPlugin"; }

 private:
  ScriptSettings settings_;
};

}  // namespace engine::script
