#pragma once
// The frame is a fixed sequence of phases. Each phase ends at a sync point
// where deferred Commands are applied (so structural changes made in a phase
// are visible to every later phase). What holds after each phase:
//
//  Startup        (first frame only) resources and initial entities exist.
//  Update         gameplay, scripts and editor tools have written their
//                 intent: Transforms, lights and settings for this frame.
//  PostUpdate     every entity with a Transform has a WorldTransform that
//                 matches its parent chain; WorldTransform is marked Changed
//                 only where its value actually changed.
//  PrepareRender  render-side mirrors (acceleration structures, GPU buffers,
//                 light lists) agree with this frame's WorldTransforms.
//  Render         this frame's images and per-frame caches (probes, G-buffers)
//                 are computed.
//  Present        images have been written or shown; frame statistics logged.
#include <array>
#include <cstdint>
#include <string_view>

namespace engine::schedule {

enum class Phase : std::uint8_t { Startup, Update, PostUpdate, PrepareRender, Render, Present };

inline constexpr std::size_t kPhaseCount = 6;

// Phases that run every frame, in order (Startup runs once before them).
inline constexpr std::array<Phase, 5> kFramePhases = {Phase::Update, Phase::PostUpdate, Phase::PrepareRender,
                                                     Phase::Render, Phase::Present};

constexpr std::string_view phase_name(Phase p) {
  constexpr std::array<std::string_view, kPhaseCount> names = {"Startup",       "Update", "PostUpdate",
                                                               "PrepareRender", "Render", "Present"};
  return names[static_cast<std::size_t>(p)];
}

}  // namespace engine::schedule
