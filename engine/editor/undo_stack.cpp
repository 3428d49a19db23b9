#include "engine/editor/undo_stack.h"

namespace engine::editor {

void UndoStack::push(const TransformEdit& edit) {
  if (edit.before == edit.after) return;
  done_.push_back(edit);
  if (done_.size() > capacity_) done_.erase(done_.begin());
  undone_.clear();
}

namespace {
bool apply(ecs::World& world, ecs::Entity e, const transform::Transform& t) {
  if (!world.alive(e)) return false;
  auto* x = world.try_get_mut<transform::Transform>(e);
  if (!x) return false;
  *x = t;
  return true;
}
}  // namespace

bool UndoStack::undo(ecs::World& world) {
  while (!done_.empty()) {
    TransformEdit e = done_.back();
    done_.pop_back();
    if (apply(world, e.entity, e.before)) {
      undone_.push_back(e);
      return true;
    }
  }
  return false;
}

bool UndoStack::redo(ecs::World& world) {
  while (!undone_.empty()) {
    TransformEdit e = undone_.back();
    undone_.pop_back();
    if (apply(world, e.entity, e.after)) {
      done_.push_back(e);
      return true;
    }
  }
  return false;
}

}  // namespace engine::editor
