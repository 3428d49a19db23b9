#pragma once
// A feature registers its components, resources and systems in build().
#include <string_view>

namespace engine::app {

class App;

class Plugin {
 public:
  virtual ~Plugin() = default;
  virtual void build(App& app) = 0;
  // Unique name; adding a plugin whose name is already present is a no-op,
  // so plugins can add the plugins they depend on.
  [[nodiscard]] virtual std::string_view name() const = 0;
};

}  // namespace engine::app
