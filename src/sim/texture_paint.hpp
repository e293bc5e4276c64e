#pragma once
// Small painting toolkit for procedural textures. Canvases are CV_32F, display-referred values in [0, 1]
// (like a photograph). Noise is periodic over the canvas so tiled textures have no seams; shapes drawn with
// the *Wrapped helpers wrap around the borders for the same reason. Anti-aliased shapes and text come from
// OpenCV's drawing functions, rendered into 8-bit coverage masks.
#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "hash.hpp"

namespace mcslam::sim::paint {

// Smooth periodic value noise in [-1, 1] with cells_x by cells_y lattice cells over the canvas.
void addValueNoise(cv::Mat& img, uint64_t seed, int cells_x, int cells_y, float amplitude);

// Sum of octaves from `largest` to `smallest` period (texels), amplitude ~ period^beta (beta = 1: the 1/f
// spectrum of natural images). `amplitude` is that of the largest octave. stretch_x > 1 elongates along x.
void addFbm(cv::Mat& img, uint64_t seed, double largest, double smallest, float amplitude, double beta = 1.0,
            double stretch_x = 1.0);

// A fresh noise field (zero mean, about [-1, 1]).
cv::Mat fbm(int w, int h, uint64_t seed, double largest, double smallest, double beta = 1.0, double stretch_x = 1.0);

// Draws with `draw(mask, offset)` into an 8-bit coverage mask covering `bounds` (shape coordinates minus
// offset), then blends `value` with the given opacity where covered.
using DrawFn = std::function<void(cv::Mat& mask, cv::Point offset)>;
void blendShape(cv::Mat& img, cv::Rect bounds, float value, float opacity, const DrawFn& draw);
// The same, repeated at +-width/height so that shapes crossing the border reappear on the other side.
void blendShapeWrapped(cv::Mat& img, cv::Rect bounds, float value, float opacity, const DrawFn& draw);

// Adds (rather than blends) delta * coverage.
void addShape(cv::Mat& img, cv::Rect bounds, float delta, const DrawFn& draw);

void fillRect(cv::Mat& img, cv::Rect r, float value, float opacity = 1.f);
void fillCircle(cv::Mat& img, cv::Point2f c, float radius, float value, float opacity = 1.f, bool wrap = false);
void drawLine(cv::Mat& img, cv::Point2f a, cv::Point2f b, float thickness, float value, float opacity = 1.f,
              bool wrap = false);
// Text with an OpenCV Hershey font; `origin` is the baseline start. Returns the text's width in texels.
int drawText(cv::Mat& img, const std::string& text, cv::Point origin, int font, double scale, int thickness,
             float value, float opacity = 1.f);
// Vertical text (rotated 90 degrees), reading bottom to top, inside the rectangle.
void drawVerticalText(cv::Mat& img, const std::string& text, cv::Rect r, int font, double scale, int thickness,
                      float value);

// Random letters grouped into words: "Tqe wuxb rena".
std::string randomWords(Rng& rng, int words, bool capitalise = true);
// A random upper-case heading or code ("EXIT", "B-204").
std::string randomHeading(Rng& rng);
int randomFont(Rng& rng);

// Vertical shading gradient over a rectangle (value at top, value at bottom), optional 0..1 opacity.
void gradientRect(cv::Mat& img, cv::Rect r, float top, float bottom);
// Raised or sunken panel edge: light on the top-left, dark on the bottom-right.
void bevel(cv::Mat& img, cv::Rect r, int width, float light, float dark);

// Converts to 8 bit with clamping.
std::vector<uint8_t> toBytes(const cv::Mat& img);

}  // namespace mcslam::sim::paint
