#pragma once
// Undo and redo of editor edits, one entry per finished gizmo drag (or
// inspector change): the entity and its Transform before and after. Entries
// hold entity handles; undoing an edit of a despawned entity is skipped.
#include <cstddef>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/transform/transform.h"

namespace engine::editor {

struct TransformEdit {
  ecs::Entity entity;
  transform::Transform before, after;
};

class UndoStack {
 public:
  explicit UndoStack(std::size_t capacity = 256) : capacity_(capacity) {}
  // Records a finished edit (a drag that moved nothing is not recorded) and
  // drops the redo history.
  void push(const TransformEdit& edit);
  // Restores `before` / `after`. False when there is nothing to undo / redo.
  bool undo(ecs::World& world);
  bool redo(ecs::World& world);
  [[nodiscard]] std::size_t undo_count() const { return done_.size(); }
  [[nodiscard]] std::size_t redo_count() const { return undone_.size(); }

 private:
  std::size_t capacity_;
  std::vector<TransformEdit> done_, undone_;
};

}  // namespace engine::editor
