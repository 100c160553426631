// The rasterising half of the GPU layer (gpu/graphics.h): names released on destruction,
// framebuffer checks that say what is missing, state scopes that restore, texture round trips, draws
// through the queue. Raw GL here only observes what the wrappers did.
#include "gpu/graphics.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/params.h"
#include "gpu/shader_library.h"
#include "shaders/test/bindings.h"

namespace ts::gpu {
namespace {

Context& context() {
  static Context shared;
  return shared;
}

// The message of the GpuError `work` throws; empty when it throws none.
template <typename F>
std::string gpu_error_of(F&& work) {
  try {
    work();
    return {};
  } catch (const GpuError& e) {
    return e.what();
  }
}

// Expects a GpuError from `work` whose message holds every one of `parts`.
template <typename F>
void expect_gpu_error_naming(F&& work, std::initializer_list<const char*> parts) {
  const std::string message = gpu_error_of(work);
  EXPECT_FALSE(message.empty()) << "expected a GpuError";
  for (const char* part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << part << " not in: " << message;
}

std::array<GLint, 4> current_viewport() {
  std::array<GLint, 4> box{};
  glGetIntegerv(GL_VIEWPORT, box.data());
  return box;
}

GLint current_integer(GLenum name) {
  GLint value = 0;
  glGetIntegerv(name, &value);
  return value;
}

TEST(Graphics, TextureFramebufferAndVertexArrayNamesAreReleasedOnDestruction) {
  context();
  GLuint texture = 0, framebuffer = 0, vertex_array = 0;
  {
    const Texture t = Texture::create_2d(GL_RGBA8, 4, 4, "test colour");
    const Framebuffer f("test target");
    const VertexArray v = VertexArray::create();
    texture = t.id();
    framebuffer = f.id();
    vertex_array = v.id();
    EXPECT_TRUE(glIsTexture(texture));
    EXPECT_TRUE(glIsFramebuffer(framebuffer));
    EXPECT_TRUE(glIsVertexArray(vertex_array));
  }
  EXPECT_FALSE(glIsTexture(texture));
  EXPECT_FALSE(glIsFramebuffer(framebuffer));
  EXPECT_FALSE(glIsVertexArray(vertex_array));
}

TEST(Graphics, MovingATextureHandsOverItsNameAndEmptiesTheSource) {
  context();
  Texture a = Texture::create_3d(GL_R32F, 2, 3, 4, "test volume");
  const GLuint id = a.id();
  Texture b = std::move(a);
  EXPECT_TRUE(a.empty());  // NOLINT(bugprone-use-after-move): moved from on purpose
  EXPECT_EQ(a.bytes(), 0u);
  EXPECT_EQ(b.id(), id);
  EXPECT_EQ(b.bytes(), 2u * 3u * 4u * 4u);
  b = Texture();
  EXPECT_FALSE(glIsTexture(id));
}

TEST(Graphics, FramebufferWithADrawBufferButNoColourAttachmentThrowsNamingIt) {
  context();
  const Texture colour = Texture::create_2d(GL_RGBA8, 4, 4, "test colour");
  Framebuffer target("test target");
  target.attach_color(0, colour);
  target.set_draw_buffers(2);
  expect_gpu_error_naming([&] { target.check_complete(); },
                          {"'test target'", "no colour attachment 1", "colour 0 'test colour'"});
}

TEST(Graphics, FramebufferWithNothingAttachedThrowsGlsMissingAttachmentStatus) {
  context();
  Framebuffer target("empty target");
  target.set_draw_buffers(0);
  expect_gpu_error_naming(
      [&] { target.check_complete(); },
      {"'empty target'", "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT", "nothing attached"});
}

TEST(Graphics, CompleteFramebufferPassesTheCheckAndClearsEachAttachment) {
  context();
  const Texture colour = Texture::create_2d(GL_RGBA32F, 3, 2, "test colour");
  const Texture depth = Texture::create_2d(GL_DEPTH_COMPONENT32F, 3, 2, "test depth");
  Framebuffer target("test target");
  target.attach_color(0, colour);
  target.attach_depth(depth);
  EXPECT_NO_THROW(target.check_complete());
  target.clear_color(0, {0.25f, 0.5f, 0.75f, 1.0f});
  target.clear_depth(0.375f);
  std::vector<float> rgba(4 * 6), depths(6);
  colour.read(rgba.data(), rgba.size() * sizeof(float), GL_RGBA, GL_FLOAT);
  depth.read(depths.data(), depths.size() * sizeof(float), GL_DEPTH_COMPONENT, GL_FLOAT);
  for (int p = 0; p < 6; ++p) {
    EXPECT_EQ(rgba[4 * p + 0], 0.25f);
    EXPECT_EQ(rgba[4 * p + 2], 0.75f);
    EXPECT_EQ(depths[p], 0.375f);
  }
}

TEST(Graphics, StateScopeRestoresDepthTestAndViewportAfterAnException) {
  context();
  glDisable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  glViewport(1, 2, 3, 4);
  try {
    StateScope scope;
    scope.depth_test(GL_LESS).viewport(64, 32);
    EXPECT_TRUE(glIsEnabled(GL_DEPTH_TEST));
    EXPECT_EQ(current_integer(GL_DEPTH_FUNC), GL_LESS);
    EXPECT_EQ(current_viewport(), (std::array<GLint, 4>{0, 0, 64, 32}));
    throw std::runtime_error("a pass failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
  EXPECT_EQ(current_integer(GL_DEPTH_FUNC), GL_GREATER);
  GLboolean write = GL_TRUE;
  glGetBooleanv(GL_DEPTH_WRITEMASK, &write);
  EXPECT_EQ(write, GL_FALSE);
  EXPECT_EQ(current_viewport(), (std::array<GLint, 4>{1, 2, 3, 4}));
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
}

TEST(Graphics, NestedStateScopesRestoreCullingBlendFramebufferAndVertexArrayInTurn) {
  context();
  glEnable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  const Framebuffer target("test target");
  const VertexArray vertices = VertexArray::create();
  {
    StateScope outer;
    outer.framebuffer(target).vertex_array(vertices).cull(GL_FRONT);
    {
      StateScope inner;
      inner.no_cull().no_blend();
      EXPECT_FALSE(glIsEnabled(GL_CULL_FACE));
      EXPECT_FALSE(glIsEnabled(GL_BLEND));
    }
    EXPECT_TRUE(glIsEnabled(GL_CULL_FACE));
    EXPECT_EQ(current_integer(GL_CULL_FACE_MODE), GL_FRONT);
    EXPECT_TRUE(glIsEnabled(GL_BLEND));
    EXPECT_EQ(current_integer(GL_DRAW_FRAMEBUFFER_BINDING), static_cast<GLint>(target.id()));
    EXPECT_EQ(current_integer(GL_READ_FRAMEBUFFER_BINDING), static_cast<GLint>(target.id()));
    EXPECT_EQ(current_integer(GL_VERTEX_ARRAY_BINDING), static_cast<GLint>(vertices.id()));
  }
  EXPECT_FALSE(glIsEnabled(GL_CULL_FACE));
  EXPECT_EQ(current_integer(GL_CULL_FACE_MODE), GL_BACK);
  EXPECT_EQ(current_integer(GL_DRAW_FRAMEBUFFER_BINDING), 0);
  EXPECT_EQ(current_integer(GL_VERTEX_ARRAY_BINDING), 0);
  glDisable(GL_BLEND);
}

TEST(Graphics, ArrayTextureLayersRoundTripThroughUploadAndRead) {
  context();
  Texture layers = Texture::create_2d_array(GL_RGBA32F, 3, 2, 4, "test layers");
  std::vector<float> written(4 * 3 * 2 * 2);
  std::iota(written.begin(), written.end(), 1.0f);
  layers.upload(written.data(), GL_RGBA, GL_FLOAT, 1, 2);
  std::vector<float> read(written.size(), -1.0f);
  layers.read(read.data(), read.size() * sizeof(float), GL_RGBA, GL_FLOAT, 1, 2);
  EXPECT_EQ(read, written);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(Graphics, ArrayLayersCopyIntoA3dTextureAtASliceOffset) {
  context();
  Texture slab = Texture::create_2d_array(GL_RGBA32F, 2, 2, 3, "test slab");
  Texture volume = Texture::create_3d(GL_RGBA32F, 2, 2, 5, "test volume");
  std::vector<float> values(4 * 2 * 2 * 3);
  std::iota(values.begin(), values.end(), 0.5f);
  slab.upload(values.data(), GL_RGBA, GL_FLOAT);
  slab.copy_to(volume, 2, 3);
  std::vector<float> slices(values.size());
  volume.read(slices.data(), slices.size() * sizeof(float), GL_RGBA, GL_FLOAT, 2, 3);
  EXPECT_EQ(slices, values);
  expect_gpu_error_naming([&] { slab.copy_to(volume, 3, 3); }, {"'test volume'"});
}

TEST(Graphics, SamplingAndDepthCompareSetEveryAxisOfTheTexture) {
  context();
  Texture volume = Texture::create_3d(GL_R16F, 2, 2, 2, "test volume");
  volume.set_sampling(GL_LINEAR);
  Texture shadow = Texture::create_2d(GL_DEPTH_COMPONENT32F, 2, 2, "test shadow");
  shadow.set_depth_compare(GL_LEQUAL);
  auto parameter = [](const Texture& t, GLenum name) {
    GLint value = 0;
    glGetTextureParameteriv(t.id(), name, &value);
    return value;
  };
  EXPECT_EQ(parameter(volume, GL_TEXTURE_MAG_FILTER), GL_LINEAR);
  EXPECT_EQ(parameter(volume, GL_TEXTURE_WRAP_R), GL_CLAMP_TO_EDGE);
  EXPECT_EQ(parameter(shadow, GL_TEXTURE_COMPARE_MODE), GL_COMPARE_REF_TO_TEXTURE);
  EXPECT_EQ(parameter(shadow, GL_TEXTURE_COMPARE_FUNC), GL_LEQUAL);
}

TEST(Graphics, ImageBindingUnbindsItsUnitWhenItEnds) {
  context();
  const Texture volume = Texture::create_3d(GL_RGBA32F, 2, 2, 2, "test volume");
  GLint bound = 0;
  {
    const ImageBinding binding(3, volume, GL_READ_WRITE);
    glGetIntegeri_v(GL_IMAGE_BINDING_NAME, 3, &bound);
    EXPECT_EQ(bound, static_cast<GLint>(volume.id()));
    glGetIntegeri_v(GL_IMAGE_BINDING_LAYERED, 3, &bound);
    EXPECT_EQ(bound, GL_TRUE);
  }
  glGetIntegeri_v(GL_IMAGE_BINDING_NAME, 3, &bound);
  EXPECT_EQ(bound, 0);
}

TEST(Graphics, DrawArraysFillsTheTargetAndIsTimedUnderItsName) {
  context();
  ShaderLibrary library;
  const Program solid = Program::graphics(library, "preview/shade.vert", "", "test/solid_color.frag");
  ParamBlock<params::SolidColorParams> params;
  params.values.color = {0.0f, 1.0f, 0.0f, 1.0f};
  params.bind(TS_TEST_PARAMS);
  const Texture colour = Texture::create_2d(GL_RGBA8, 5, 3, "test colour");
  Framebuffer target("test target");
  target.attach_color(0, colour);
  target.check_complete();
  const VertexArray vertices = VertexArray::create();
  Queue queue(/*timings=*/true, /*check_errors=*/true);
  {
    StateScope scope;
    scope.framebuffer(target).viewport(5, 3).vertex_array(vertices).no_depth_test();
    draw_arrays(queue, solid, GL_TRIANGLES, 0, 3, "test/full screen");
  }
  std::vector<std::uint8_t> rgba(4 * 15);
  colour.read(rgba.data(), rgba.size(), GL_RGBA, GL_UNSIGNED_BYTE);
  for (int p = 0; p < 15; ++p) EXPECT_EQ(rgba[4 * p + 1], 255) << "pixel " << p;
  const auto timings = queue.timings();
  ASSERT_EQ(timings.size(), 1u);
  EXPECT_EQ(timings[0].name, "test/full screen");
  EXPECT_EQ(timings[0].calls, 1u);
}

TEST(Graphics, DrawWithoutAVertexArrayIsAGpuErrorNamingTheProgramWhenTheQueueChecks) {
  context();
  ShaderLibrary library;
  const Program solid = Program::graphics(library, "preview/shade.vert", "", "test/solid_color.frag");
  const Texture colour = Texture::create_2d(GL_RGBA8, 2, 2, "test colour");
  Framebuffer target("test target");
  target.attach_color(0, colour);
  Queue queue(/*timings=*/false, /*check_errors=*/true);
  StateScope scope;
  scope.framebuffer(target).viewport(2, 2);
  glBindVertexArray(0);  // a core context has no default vertex array: the draw is invalid
  expect_gpu_error_naming([&] { draw_arrays(queue, solid, GL_TRIANGLES, 0, 3); },
                          {"GL_INVALID_OPERATION", "test/solid_color.frag"});
}

TEST(Graphics, TextureReadPastTheLastLayerThrowsNamingTheTexture) {
  context();
  const Texture layers = Texture::create_2d_array(GL_R32F, 2, 2, 2, "test layers");
  std::vector<float> out(2 * 2 * 3);
  expect_gpu_error_naming(
      [&] { layers.read(out.data(), out.size() * sizeof(float), GL_RED, GL_FLOAT, 0, 3); },
      {"'test layers'"});
}

}  // namespace
}  // namespace ts::gpu
