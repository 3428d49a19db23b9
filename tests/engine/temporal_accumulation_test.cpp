// Temporal accumulation for a still view: the first `window` frames average
// exactly, later ones enter with weight 1/window, and any change of the view
// key restarts from the new frame.
#include <gtest/gtest.h>

#include "engine/render/temporal_accumulation.h"

using namespace engine;

TEST(TemporalAccumulation, AveragesAStillViewAndRestartsWhenItChanges) {
  render::TemporalAccumulation h;
  auto frame = [](float v) { return image::ImageRGB(2, 1, glm::vec3(v)); };
  const std::uint64_t key = render::view_key(transform::Similarity{}, 2, 1, 7, 9);
  for (float v : {1.0f, 2.0f, 3.0f, 4.0f}) render::accumulate(h, frame(v), key, 4);
  EXPECT_FLOAT_EQ(h.average.pixels[1].g, 2.5f) << "the mean of 1, 2, 3, 4";
  render::accumulate(h, frame(6.5f), key, 4);
  EXPECT_FLOAT_EQ(h.average.pixels[0].r, 2.5f + (6.5f - 2.5f) / 4) << "past the window: weight 1/4";
  transform::Similarity moved;
  moved.translation.x = 1e-3f;
  EXPECT_NE(render::view_key(moved, 2, 1, 7, 9), key);
  EXPECT_NE(render::view_key(transform::Similarity{}, 2, 1, 8, 9), key) << "geometry moved";
  EXPECT_NE(render::view_key(transform::Similarity{}, 2, 1, 7, 10), key) << "lights changed";
  render::accumulate(h, frame(10.0f), render::view_key(moved, 2, 1, 7, 9), 4);
  EXPECT_FLOAT_EQ(h.average.pixels[0].b, 10.0f) << "a moved camera restarts";
  EXPECT_FLOAT_EQ(render::accumulate(h, frame(3.0f), key, 1).pixels[0].g, 3.0f) << "window 1 = off";
}
