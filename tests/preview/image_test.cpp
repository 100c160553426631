// PNG files (atomic, lossless round trip), contact sheets, image comparison.
#include "preview/image.h"

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

Image gradient(int w, int h, bool alpha) {
  Image im;
  im.width = w;
  im.height = h;
  im.alpha = alpha;
  im.rgba.resize(4 * static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = im.pixel(x, y);
      p[0] = static_cast<std::uint8_t>(x * 7);
      p[1] = static_cast<std::uint8_t>(y * 13);
      p[2] = static_cast<std::uint8_t>(x ^ y);
      p[3] = alpha ? static_cast<std::uint8_t>(x + y) : 255;
    }
  }
  return im;
}

TEST(Png, RoundTripIsLossless) {
  const auto dir = test::temp_dir();
  for (bool alpha : {false, true}) {
    const Image im = gradient(37, 21, alpha);
    write_png(dir / "a.png", im);
    const Image back = read_png(dir / "a.png");
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 21);
    EXPECT_EQ(back.alpha, alpha);
    EXPECT_EQ(back.rgba, im.rgba);
  }
  // Atomic: nothing but the file itself is left in the directory.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
}

TEST(Png, NeverOverwritesAnInputAndRejectsNonPngs) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "mesh.obj", "v 0 0 0\n");
  EXPECT_THROW(write_png(dir / "mesh.obj", gradient(4, 4, false), {dir / "mesh.obj"}), InputError);
  EXPECT_EQ(read_file(dir / "mesh.obj"), "v 0 0 0\n");
  EXPECT_THROW(read_png(dir / "mesh.obj"), InputError);
  EXPECT_THROW(read_png(dir / "missing.png"), InputError);
  EXPECT_THROW(write_png(dir / "empty.png", Image{}), InputError);
}

TEST(Png, ContactSheetTilesRowByRow) {
  std::vector<Image> views;
  for (int k = 0; k < 5; ++k) {
    Image im = gradient(4, 3, false);
    im.pixel(0, 0)[0] = static_cast<std::uint8_t>(100 + k);
    views.push_back(im);
  }
  const Image sheet = contact_sheet(views);  // 3 columns, 2 rows
  EXPECT_EQ(sheet.width, 12);
  EXPECT_EQ(sheet.height, 6);
  EXPECT_EQ(sheet.pixel(4, 0)[0], 101);
  EXPECT_EQ(sheet.pixel(4, 3)[0], 104);
  EXPECT_EQ(sheet.pixel(8, 3)[0], 255);  // the empty cell is white
  EXPECT_EQ(contact_sheet(views, 5).width, 20);
}

TEST(Png, ComparisonCountsPixelsOverTheThreshold) {
  const Image a = gradient(10, 10, false);
  Image b = a;
  b.pixel(3, 3)[1] = static_cast<std::uint8_t>(b.pixel(3, 3)[1] + 100);
  const ImageDifference d = compare_images(a, b);
  EXPECT_EQ(d.max_abs, 100);
  EXPECT_DOUBLE_EQ(d.fraction_over, 0.01);
  EXPECT_DOUBLE_EQ(compare_images(a, a).mean_abs, 0.0);
}

}  // namespace
}  // namespace ts::preview
