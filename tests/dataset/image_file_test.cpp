// Image files: our binary PGM reader (good files, and a clear error naming the file for a wrong magic, a
// malformed or truncated file, 16-bit data), the PGM writer, and PNG decoded through the image codec module that
// is loaded on first need (found from this test's executable, as mcslamd finds it), or a clear error naming the
// paths tried when it is not there.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "image_codec_loader.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/image_file.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

// A seeded random image (no two rows alike, so a stride or row-order mistake shows).
Image randomImage(int width, int height, unsigned seed) {
  Image image(width, height);
  std::mt19937 rng(seed);
  for (int i = 0; i < width * height; ++i) image.data()[i] = static_cast<uint8_t>(rng());
  return image;
}

void expectSamePixels(const Image& a, const Image& b) {
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  EXPECT_TRUE(std::equal(a.data(), a.data() + a.width() * a.height(), b.data()));
}

// The message of the InputError readPgmFile throws for the file holding `bytes` (a failure when none is thrown).
std::string pgmError(const test::TempDir& dir, const std::string& bytes) {
  const std::string path = test::writeFile(dir.file("bad.pgm"), bytes);
  Image image;
  try {
    readPgmFile(path, image);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos)
        << "the message does not name the file: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << bytes.substr(0, 20);
  return "";
}

}  // namespace

TEST(PgmFile, WrittenImageReadsBackIdentical) {
  test::TempDir dir("pgm_good");
  const Image written = randomImage(37, 23, 1);
  writePgmFile(dir.file("a.pgm"), written.view());
  EXPECT_EQ(test::readFile(dir.file("a.pgm")).substr(0, 13), "P5\n37 23\n255\n");
  Image read;
  readPgmFile(dir.file("a.pgm"), read);
  expectSamePixels(written, read);
  Image by_content;  // the general reader takes the PGM path without any module
  readGreyImageFile(dir.file("a.pgm"), by_content);
  expectSamePixels(written, by_content);
}

TEST(PgmFile, HeaderCommentsAndAnyWhitespaceAreRead) {
  test::TempDir dir("pgm_comments");
  const std::string path =
      test::writeFile(dir.file("c.pgm"), std::string("P5 # GIMP\n3\t# width\n 2\r\n255\n") + "abcdef");
  Image image;
  readPgmFile(path, image);
  ASSERT_EQ(image.width(), 3);
  ASSERT_EQ(image.height(), 2);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(image.data()), 6), "abcdef");
}

TEST(PgmFile, ReadingIntoAnImageOfTheSizeKeepsItsBuffer) {
  test::TempDir dir("pgm_reuse");
  writePgmFile(dir.file("a.pgm"), randomImage(20, 10, 2).view());
  Image image(20, 10);
  const uint8_t* buffer = image.data();
  readPgmFile(dir.file("a.pgm"), image);
  EXPECT_EQ(image.data(), buffer);
}

TEST(PgmFile, TruncatedPixelsAreAnErrorSayingHowManyBytesCame) {
  test::TempDir dir("pgm_truncated");
  const std::string error = pgmError(dir, "P5\n4 3\n255\n" + std::string(7, 'x'));
  EXPECT_NE(error.find("truncated: 7 of 12 pixel bytes (4x3)"), std::string::npos) << error;
  const std::string cut_header = pgmError(dir, "P5\n4 3");
  EXPECT_NE(cut_header.find("height missing (file truncated)"), std::string::npos) << cut_header;
}

// A file far shorter than its header claims is refused before the image takes the claimed size.
TEST(PgmFile, AShortFileClaimingAHugeImageAllocatesNothing) {
  test::TempDir dir("pgm_claim");
  const std::string path = test::writeFile(dir.file("claim.pgm"), "P5\n30000 30000\n255\n" + std::string(5, 'x'));
  Image image;
  try {
    readPgmFile(path, image);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated: 5 of 900000000 pixel bytes (30000x30000)"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(image.width(), 0);  // never resized to 30000x30000
}

TEST(PgmFile, WrongMagicIsAnErrorNamingWhatTheFileStartsWith) {
  test::TempDir dir("pgm_magic");
  const std::string ascii = pgmError(dir, "P2\n2 1\n255\n1 2\n");
  EXPECT_NE(ascii.find("not a binary PGM: starts with 'P2' (expected 'P5')"), std::string::npos) << ascii;
  const std::string png = pgmError(dir, "\x89PNG\r\n");
  EXPECT_NE(png.find("starts with '\\x89P'"), std::string::npos) << png;
}

TEST(PgmFile, SixteenBitAndOtherMaxvalsAreRefused) {
  test::TempDir dir("pgm_maxval");
  const std::string deep = pgmError(dir, "P5\n2 2\n65535\n" + std::string(8, '\0'));
  EXPECT_NE(deep.find("maxval 65535"), std::string::npos) << deep;
  EXPECT_NE(deep.find("16-bit"), std::string::npos) << deep;
  const std::string low = pgmError(dir, "P5\n2 2\n15\n" + std::string(4, '\0'));
  EXPECT_NE(low.find("maxval 15 (only 8-bit grey with maxval 255 is read)"), std::string::npos) << low;
}

TEST(PgmFile, MalformedOrHugeSizesAreRefused) {
  test::TempDir dir("pgm_size");
  const std::string word = pgmError(dir, "P5\nwide 2\n255\n");
  EXPECT_NE(word.find("PGM header: width is not a number"), std::string::npos) << word;
  const std::string zero = pgmError(dir, "P5\n0 2\n255\n");
  EXPECT_NE(zero.find("width 0 (expected 1 to 32768)"), std::string::npos) << zero;
  const std::string huge = pgmError(dir, "P5\n2 99999999999\n255\n");  // no allocation of what it claims
  EXPECT_NE(huge.find("height 1000000000 or more (expected 1 to 32768)"), std::string::npos) << huge;
}

TEST(PgmFile, AMissingFileIsNamed) {
  Image image;
  try {
    readGreyImageFile("/nonexistent/mcslam/0.pgm", image);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/mcslam/0.pgm: cannot open image"), std::string::npos)
        << e.what();
  }
}

TEST(ImageCodecModule, PngReadsBackIdenticalThroughTheModuleLoadedOnFirstUse) {
  test::TempDir dir("codec_png");
  const Image written = randomImage(41, 29, 3);
  const std::string path = dir.file("a.png");
  ASSERT_TRUE(
      cv::imwrite(path, cv::Mat(written.height(), written.width(), CV_8UC1, const_cast<uint8_t*>(written.data()))));
  Image read(5, 5);  // smaller: the module asks for the size it needs
  readGreyImageFile(path, read);
  expectSamePixels(written, read);
  // It came from the first place the loader looks: ../lib/mcslam/ next to this executable (build/bin).
  const detail::ImageCodecModule module = detail::loadImageCodecModule(imageCodecModuleCandidates());
  ASSERT_TRUE(module.read) << module.failure;
  EXPECT_EQ(module.path, imageCodecModuleCandidates().front());
}

// The message of the InputError readGreyImageFile throws for `path` read with `bound` ("" when none is thrown).
std::string boundError(const std::string& path, ImageBound bound, Image& image) {
  try {
    readGreyImageFile(path, image, bound);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A small file may claim a huge image (a PNG of 875 KB can say 30000x30000): what is larger than the camera is
// refused from its header, before any pixel is decoded, for PGM, PNG and JPEG alike.
TEST(ImageBound, AnImageLargerThanTheCameraIsRefusedBeforeDecoding) {
  test::TempDir dir("bound");
  const Image pixels = randomImage(100, 80, 5);
  const cv::Mat mat(pixels.height(), pixels.width(), CV_8UC1, const_cast<uint8_t*>(pixels.data()));
  const std::string png = dir.file("a.png"), jpg = dir.file("a.jpg"), pgm = dir.file("a.pgm");
  ASSERT_TRUE(cv::imwrite(png, mat));
  ASSERT_TRUE(cv::imwrite(jpg, mat));
  writePgmFile(pgm, pixels.view());
  for (const std::string& path : {png, jpg, pgm}) {
    Image image;
    const std::string m = boundError(path, ImageBound{64, 48}, image);
    EXPECT_NE(m.find(path + ": image is 100x80, larger than the 64x48"), std::string::npos) << path << ": " << m;
    EXPECT_EQ(image.width() * image.height(), 0) << path << ": pixels were read";
    EXPECT_EQ(boundError(path, ImageBound{100, 80}, image), "") << path;
    EXPECT_EQ(image.width(), 100) << path;
  }
  // A PNG whose header claims 30000x30000 (the pixels would not even be there): refused from the header alone.
  std::string bytes = test::readFile(png);
  const unsigned char huge[8] = {0, 0, 0x75, 0x30, 0, 0, 0x75, 0x30};
  bytes.replace(16, 8, reinterpret_cast<const char*>(huge), 8);
  const std::string claim = test::writeFile(dir.file("claim.png"), bytes);
  Image image;
  EXPECT_NE(boundError(claim, ImageBound{640, 480}, image).find("image is 30000x30000, larger than the 640x480"),
            std::string::npos);
  EXPECT_EQ(image.width() * image.height(), 0);
}

TEST(ImageCodecModule, AnUndecodableFileIsNamed) {
  test::TempDir dir("codec_bad");
  const std::string path = test::writeFile(dir.file("a.png"), "not a png at all");
  Image image;
  try {
    readGreyImageFile(path, image);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    const std::string expected = path + ": cannot read image (missing, unreadable, or not a format OpenCV decodes)";
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(ImageCodecModule, WithoutAModuleTheErrorNamesEveryPathTriedAndWhy) {
  test::TempDir dir("codec_missing");
  const std::string not_a_library = test::writeFile(dir.file("mcslam_image_codec.so"), "text");
  const detail::ImageCodecModule module =
      detail::loadImageCodecModule({"/nonexistent/mcslam_image_codec.so", not_a_library});
  EXPECT_EQ(module.read, nullptr);
  EXPECT_NE(module.failure.find("/nonexistent/mcslam_image_codec.so (no such file)"), std::string::npos)
      << module.failure;
  EXPECT_NE(module.failure.find(not_a_library + " ("), std::string::npos) << module.failure;
  EXPECT_NE(module.failure.find("--images pgm"), std::string::npos) << module.failure;
}
