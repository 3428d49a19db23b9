// The hierarchy, the inspector and saving the level.
#include <algorithm>
#include <set>
#include <cmath>
#include <map>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"
#include "engine/script/script_runtime.h"
#include "engine/transform/transform.h"
#include "level/level_save.h"
#include "runtime/components.h"
#include "runtime/probe_placement.h"
#include "runtime/settings.h"
#include "window/editor_ui.h"

namespace game {

namespace {
using engine::ecs::Entity;
namespace tf = engine::transform;

std::string label_of(engine::ecs::World& w, Entity e) {
  const auto* n = w.try_get<engine::scene::Name>(e);
  return (n ? n->value : std::string("entity")) + "##" + std::to_string(e.index);
}
}  // namespace

void EditorUi::hierarchy_node(Entity e, const std::map<Entity, std::vector<Entity>>& children_of) {
  engine::ecs::World& w = session_.world();
  static const std::vector<Entity> kNoChildren;
  const auto found = children_of.find(e);
  const std::vector<Entity>& children = found == children_of.end() ? kNoChildren : found->second;
  EditorState& ed = session_.editor();
  ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_SpanAvailWidth;
  if (children.empty()) flags |= ImGuiTreeNodeFlags_Leaf;
  if (ed.selected == e) flags |= ImGuiTreeNodeFlags_Selected;
  const bool open = ImGui::TreeNodeEx(label_of(w, e).c_str(), flags);
  if (ImGui::IsItemClicked()) ed.selected = e;
  if (open) {
    for (Entity c : children) hierarchy_node(c, children_of);
    ImGui::TreePop();
  }
}

void EditorUi::hierarchy() {
  ImGui::SetNextWindowPos(ImVec2(8, 40), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(240, 380), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Hierarchy")) {
    ImGui::End();
    return;
  }
  engine::ecs::World& w = session_.world();
  std::vector<Entity> roots;
  w.view<const engine::scene::Name>().each([&](Entity e, const engine::scene::Name&) {
    if (!w.has<tf::Parent>(e)) roots.push_back(e);
  });
  std::sort(roots.begin(), roots.end());
  // Children found in one pass, not one pass per node: levels have thousands.
  std::map<Entity, std::vector<Entity>> children_of;
  w.view<const tf::Parent>().each([&](Entity c, const tf::Parent& p) { children_of[p.entity].push_back(c); });
  for (auto& [parent, children] : children_of) std::sort(children.begin(), children.end());
  for (Entity e : roots) hierarchy_node(e, children_of);
  ImGui::End();
}

void EditorUi::inspector() {
  const ImGuiIO& io = ImGui::GetIO();
  // Wide enough for its longest labels at the default font, and every
  // widget leaves its label a fixed column (ImGui's default gives widgets
  // 65 % of the width and cuts the labels off).
  const float width = kInspectorWidthEms * ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width - 8.0f, 40), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(width, 520), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Inspector")) {
    ImGui::End();
    return;
  }
  ImGui::PushItemWidth(-kLabelColumnEms * ImGui::GetFontSize());
  engine::ecs::World& w = session_.world();
  EditorState& ed = session_.editor();
  const Entity e = ed.selected;
  if (e.is_null() || !w.alive(e)) {
    ImGui::TextDisabled("Click an object in the view or the hierarchy.");
  } else {
    const std::string label = label_of(w, e);
    ImGui::Text("%s (entity %u)", label.substr(0, label.find("##")).c_str(), e.index);
    if (const auto* t = w.try_get<tf::Transform>(e); t && ImGui::CollapsingHeader("Transform", ImGuiTreeNodeFlags_DefaultOpen)) {
      tf::Transform edit = *t;
      glm::vec3 euler = glm::degrees(glm::eulerAngles(edit.rotation));
      bool changed = ImGui::DragFloat3("position", &edit.translation.x, 0.01f);
      if (ImGui::DragFloat3("rotation", &euler.x, 0.5f, -360.0f, 360.0f, "%.1f deg")) {
        edit.rotation = glm::quat(glm::radians(euler));
        changed = true;
      }
      changed |= ImGui::DragFloat("scale", &edit.scale, 0.005f, 0.01f, 100.0f);
      if (ImGui::IsItemActivated() || (changed && !editing_transform_)) {
        editing_transform_ = true;
        edit_start_ = *t;
      }
      if (changed && std::isfinite(edit.translation.x + edit.translation.y + edit.translation.z + edit.scale) && edit.scale > 0)
        w.get_mut<tf::Transform>(e) = edit;
      if (editing_transform_ && !ImGui::IsAnyItemActive()) {  // one undo entry per edit
        ed.undo.push({e, edit_start_, w.get<tf::Transform>(e)});
        editing_transform_ = false;
      }
    }
    if (const auto* l = w.try_get<engine::scene::PunctualLight>(e); l && ImGui::CollapsingHeader("Light", ImGuiTreeNodeFlags_DefaultOpen)) {
      engine::scene::PunctualLight edit = *l;
      bool changed = ImGui::Checkbox("enabled", &edit.enabled);
      changed |= ImGui::ColorEdit3("colour", &edit.color.x);
      changed |= ImGui::DragFloat("intensity", &edit.intensity, 0.02f, 0.0f, 1e4f);
      changed |= ImGui::DragFloat("range (0 = infinite)", &edit.range, 0.05f, 0.0f, 1e4f);
      if (changed) w.get_mut<engine::scene::PunctualLight>(e) = edit;
    }
    if (const auto* m = w.try_get<engine::scene::MeshInstance>(e); m && ImGui::CollapsingHeader("Material")) {
      // Run-time material knobs: TransGI takes albedo as a network input, so
      // a colour change needs no re-bake. A material is shared by every
      // mesh that uses it.
      auto& assets = w.resource<engine::scene::SceneAssets>();
      std::set<std::uint32_t> used;
      if (m->mesh < assets.meshes.size())
        for (std::uint32_t id : assets.meshes[m->mesh]->triangle_material) used.insert(id);
      for (std::uint32_t id : used) {
        if (id >= assets.materials.size()) continue;
        engine::material::Material& mat = assets.materials[id];
        ImGui::PushID(static_cast<int>(id));
        ImGui::Text("%s (material %u)", mat.name.c_str(), id);
        bool changed = ImGui::ColorEdit3("base colour", &mat.base_color_factor.x);
        changed |= ImGui::SliderFloat("roughness", &mat.roughness_factor, 0.0f, 1.0f);
        changed |= ImGui::SliderFloat("metallic", &mat.metallic_factor, 0.0f, 1.0f);
        changed |= ImGui::DragFloat("emission strength", &mat.emissive_strength, 0.05f, 0.0f, 1000.0f);
        if (changed) ++assets.edit_version;  // the light set and probes follow
        ImGui::PopID();
      }
    }
    if (const auto* s = w.try_get<engine::script::Script>(e); s && ImGui::CollapsingHeader("Script", ImGuiTreeNodeFlags_DefaultOpen)) {
      auto& runtime = w.resource<engine::script::ScriptRuntime>();
      ImGui::Text("%s  %s", s->path.c_str(), runtime.is_enabled(e) ? "(running)" : "(stopped: see the log)");
      for (engine::script::ScriptProperty& p : runtime.properties(e)) {
        if (double* d = std::get_if<double>(&p.value)) {
          float v = static_cast<float>(*d);
          if (ImGui::DragFloat(p.name.c_str(), &v, 0.01f)) runtime.set_property(w, e, p.name, static_cast<double>(v));
        } else if (bool* b = std::get_if<bool>(&p.value)) {
          if (ImGui::Checkbox(p.name.c_str(), b)) runtime.set_property(w, e, p.name, *b);
        } else {
          ImGui::Text("%s = \"%s\"", p.name.c_str(), std::get<std::string>(p.value).c_str());
        }
      }
    }
  }
  gi_settings();
  ImGui::PopItemWidth();
  ImGui::End();
}

void EditorUi::gi_settings() {
  engine::ecs::World& w = session_.world();
  if (!ImGui::CollapsingHeader("TransGI settings")) return;
  auto* s = w.try_resource<transgi::runtime::TransGISettings>();
  if (!s) return;
  transgi::runtime::TransGISettings edit = *s;
  bool changed = ImGui::SliderFloat("GI resolution", &edit.realtime.resolution_scale, 0.25f, 1.0f, "%.2f");
  changed |= ImGui::SliderFloat("depth tolerance", &edit.realtime.depth_tolerance, 0.01f, 0.5f, "%.2f");
  changed |= ImGui::SliderInt("normal power", &edit.realtime.normal_power, 1, 64);
  changed |= ImGui::Checkbox("edge-aware upsampling", &edit.realtime.edge_aware);
  changed |= ImGui::Checkbox("reuse last frame's GI (checkerboard)", &edit.realtime.reuse_history);
  // Frames a cell keeps its decoded transfer (0 = off), and the view turn that re-decodes it.
  changed |= ImGui::SliderInt("keep transfer", &edit.realtime.transfer_max_age, 0, 128);
  changed |= ImGui::SliderFloat("transfer view turn", &edit.realtime.transfer_view_degrees, 0.0f, 30.0f, "%.1f deg");
  changed |= ImGui::SliderInt("probe budget / frame", &edit.probes.update_budget, 0, 512);
  // The budget once the lights have held (objects may move); 0 = the one above.
  changed |= ImGui::SliderInt("steady-light budget", &edit.probes.steady_light_budget, 0, 512);
  // Traced reflections (shading::MirrorRay); off is the paper's SH-4 transfer alone.
  bool reflections = edit.mirror.max_roughness >= 0;
  if (ImGui::Checkbox("traced reflections", &reflections)) {
    edit.mirror.max_roughness = reflections ? transgi::shading::MirrorRay{}.max_roughness : -1.0f;
    changed = true;
  }
  // Up to which roughness metals and non-metals (varnish, plastic) trace them.
  changed |= ImGui::SliderFloat("metals traced to", &edit.mirror.glossy_max_roughness, 0.0f, 1.0f, "roughness %.2f");
  changed |= ImGui::SliderFloat("others traced to", &edit.mirror.dielectric_max_roughness, -0.05f, 1.0f,
                                "roughness %.2f (<0 off)");
  changed |= ImGui::Checkbox("decode transfer on the GPU (vulkan backend)", &edit.device_inference);
  changed |= ImGui::Checkbox("make the decoded samples' light on the GPU", &edit.realtime.device_lights);
  if (changed) *s = edit;
  // The backend at run time (issue 12): Vulkan, lavapipe where there is no GPU.
  int backend = s->backend == transgi::runtime::Backend::Vulkan ? 1 : 0;
  if (ImGui::Combo("GI backend", &backend, "cpu\0vulkan\0")) session_.set_backend(backend == 1 ? "vulkan" : "cpu");
  ImGui::TextWrapped("runs on: %s", session_.backend_status().c_str());
  int index = 0;
  for (const auto& field : transgi::runtime::probe_fields(w)) {
    const auto& g = field->settings().grid;
    ImGui::Text("probe field %d: %dx%dx%d probes, %.2f m apart", index++, g.dims.x, g.dims.y, g.dims.z, g.min_spacing());
    ImGui::Text("  bounds (%.2f %.2f %.2f) - (%.2f %.2f %.2f)", g.min.x, g.min.y, g.min.z, g.max.x, g.max.y, g.max.z);
    ImGui::Text("  state %.1f MB", static_cast<double>(field->memory_bytes()) / (1 << 20));
  }
}

void EditorUi::save_level() {
  try {
    const auto path = save_level_gltf(session_.world(), session_.options().scene);
    status_ = "saved " + path.string();
  } catch (const std::exception& ex) {
    status_ = std::string("save failed: ") + ex.what();
  }
}

}  // namespace game
