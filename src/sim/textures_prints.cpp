// Man-made, fitted textures: posters, notice boards, whiteboards, book shelves, doors, cabinets, facades and
// clothing. Text and crisp shapes give the high-contrast corners that real indoor scenes are full of.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "texture_kinds.hpp"
#include "texture_paint.hpp"

namespace mcslam::sim {

using namespace paint;

namespace {

cv::Mat canvas(int w, int h, float value) { return cv::Mat(h, w, CV_32F, cv::Scalar(value)); }

cv::Point2f randomPoint(Rng& rng, cv::Rect r) {
  return {static_cast<float>(rng.uniform(r.x, r.x + r.width)), static_cast<float>(rng.uniform(r.y, r.y + r.height))};
}

// Lines of small text filling a rectangle.
void textBlock(cv::Mat& img, Rng& rng, cv::Rect r, float ink, double scale) {
  const int font = rng.chance(0.5) ? cv::FONT_HERSHEY_PLAIN : cv::FONT_HERSHEY_SIMPLEX;
  int baseline = 0;
  const int line_h = cv::getTextSize("Ag", font, scale, 1, &baseline).height + baseline + 3;
  for (int y = r.y + line_h; y <= r.y + r.height; y += line_h) {
    std::string line = randomWords(rng, rng.integer(2, 7), y == r.y + line_h);
    // Trim to the block width.
    while (!line.empty() && cv::getTextSize(line, font, scale, 1, &baseline).width > r.width) line.pop_back();
    drawText(img, line, {r.x, y}, font, scale, 1, ink);
    if (rng.chance(0.15)) y += line_h;  // paragraph break
  }
}

// A picture: overlapping shapes over a gradient, or a noise "photograph" with a horizon.
void picture(cv::Mat& img, Rng& rng, cv::Rect r, uint64_t seed) {
  if (rng.chance(0.5)) {
    gradientRect(img, r, static_cast<float>(rng.uniform(0.2, 0.9)), static_cast<float>(rng.uniform(0.1, 0.8)));
    cv::Mat roi = img(r);
    addFbm(roi, hashOf(seed, 31), r.width / 2.0, 2, 0.12f, 0.9);
    // Horizon silhouette.
    const float base = static_cast<float>(rng.uniform(0.45, 0.75));
    std::vector<cv::Point> poly{{r.x, r.y + r.height}};
    for (int i = 0; i <= 12; ++i) {
      poly.emplace_back(r.x + r.width * i / 12, r.y + static_cast<int>(r.height * (base + rng.uniform(-0.15, 0.1))));
    }
    poly.emplace_back(r.x + r.width, r.y + r.height);
    const float v = static_cast<float>(rng.uniform(0.05, 0.35));
    blendShape(img, r, v, 1.f, [&](cv::Mat& mask, cv::Point o) {
      std::vector<cv::Point> p;
      for (const cv::Point& q : poly) p.push_back(q - o);
      cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{p}, cv::Scalar(255), cv::LINE_AA);
    });
  } else {
    fillRect(img, r, static_cast<float>(rng.uniform(0.1, 0.9)));
    for (int i = 0; i < rng.integer(3, 9); ++i) {
      const float v = static_cast<float>(rng.uniform(0.0, 1.0));
      if (rng.chance(0.5)) {
        const cv::Point2f c = randomPoint(rng, r);
        const float rad = static_cast<float>(rng.uniform(0.05, 0.35) * std::min(r.width, r.height));
        blendShape(img, r, v, 1.f, [&](cv::Mat& mask, cv::Point o) {
          cv::circle(mask, cv::Point(c) - o, static_cast<int>(rad), cv::Scalar(255), cv::FILLED, cv::LINE_AA);
        });
      } else {
        const cv::Point2f a = randomPoint(rng, r), b = randomPoint(rng, r);
        blendShape(img, r, v, 1.f, [&](cv::Mat& mask, cv::Point o) {
          cv::rectangle(mask, cv::Point(a) - o, cv::Point(b) - o, cv::Scalar(255), cv::FILLED, cv::LINE_AA);
        });
      }
    }
  }
}

}  // namespace

PaintedTexture paintPoster(uint64_t seed) {
  Rng rng(seed);
  const int W = 512, H = 512;
  const bool dark = rng.chance(0.3);
  const float bg = dark ? static_cast<float>(rng.uniform(0.05, 0.25)) : static_cast<float>(rng.uniform(0.75, 0.95));
  const float ink = dark ? 0.92f : static_cast<float>(rng.uniform(0.02, 0.15));
  cv::Mat img = canvas(W, H, bg);
  const int margin = rng.integer(16, 40);
  // Title.
  const int font = randomFont(rng);
  const std::string title = randomHeading(rng);
  double scale = 3.0;
  int baseline = 0;
  while (scale > 0.6 && cv::getTextSize(title, font, scale, 3, &baseline).width > W - 2 * margin) scale *= 0.85;
  drawText(img, title, {margin, margin + static_cast<int>(30 * scale)}, font, scale,
           std::max(1, static_cast<int>(scale * 1.5)), ink);
  const int top = margin + static_cast<int>(40 * scale) + 10;
  // A picture and text, in one of a few layouts.
  const int layout = rng.integer(0, 2);
  if (layout == 0) {
    picture(img, rng, cv::Rect(margin, top, W - 2 * margin, (H - top) / 2), seed);
    textBlock(img, rng, cv::Rect(margin, top + (H - top) / 2 + 10, W - 2 * margin, (H - top) / 2 - margin - 10), ink,
              1.0);
  } else if (layout == 1) {
    picture(img, rng, cv::Rect(margin, top, (W - 2 * margin) / 2 - 8, H - top - margin), seed);
    textBlock(img, rng, cv::Rect(W / 2 + 8, top, W / 2 - margin - 8, H - top - margin), ink, 0.9);
  } else {
    textBlock(img, rng, cv::Rect(margin, top, W - 2 * margin, H - top - margin - 90), ink, 1.1);
    for (int i = 0; i < 4; ++i) {  // a row of logos
      const cv::Point2f c(margin + 50.f + i * 110.f, H - margin - 40.f);
      fillCircle(img, c, 32.f, static_cast<float>(rng.uniform(0, 1)));
      drawText(img, randomHeading(rng).substr(0, 2), cv::Point(c) + cv::Point(-18, 10), cv::FONT_HERSHEY_DUPLEX, 1.0, 2,
               static_cast<float>(rng.uniform(0, 1)));
    }
  }
  if (rng.chance(0.5)) bevel(img, cv::Rect(0, 0, W, H), 6, ink, ink);  // printed border
  return {img, false};
}

PaintedTexture paintNoticeBoard(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 512;
  cv::Mat img = canvas(W, H, static_cast<float>(rng.uniform(0.42, 0.55)));
  addFbm(img, hashOf(seed, 1), 8, 1, 0.10f, 0.2);  // cork
  addFbm(img, hashOf(seed, 2), 256, 32, 0.03f, 0.5);
  for (int i = 0; i < rng.integer(7, 13); ++i) {
    const int w = rng.integer(110, 220), h = rng.integer(140, 290);
    const int x = rng.integer(20, W - w - 20), y = rng.integer(20, H - h - 20);
    const float paper = static_cast<float>(rng.uniform(0.78, 0.97));
    fillRect(img, cv::Rect(x + 4, y + 4, w, h), 0.15f, 0.35f);  // shadow
    fillRect(img, cv::Rect(x, y, w, h), paper);
    const float ink = static_cast<float>(rng.uniform(0.0, 0.2));
    drawText(img, randomHeading(rng), {x + 8, y + 28}, cv::FONT_HERSHEY_DUPLEX, 0.7, 2, ink);
    if (rng.chance(0.4)) picture(img, rng, cv::Rect(x + 8, y + 38, w - 16, h / 3), hashOf(seed, i));
    textBlock(img, rng, cv::Rect(x + 8, y + (h > 200 ? h / 3 + 44 : 40), w - 16, h - (h > 200 ? h / 3 + 52 : 48)), ink,
              0.6);
    fillCircle(img, {static_cast<float>(x + w / 2), static_cast<float>(y + 8)}, 5.f,
               static_cast<float>(rng.uniform(0.05, 0.8)));
  }
  bevel(img, cv::Rect(0, 0, W, H), 14, 0.85f, 0.55f);
  return {img, false};
}

PaintedTexture paintWhiteboard(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 512;
  cv::Mat img = canvas(W, H, static_cast<float>(rng.uniform(0.88, 0.95)));
  addFbm(img, hashOf(seed, 1), 512, 64, 0.03f, 0.5);  // ghosts of erased writing
  for (int i = 0; i < rng.integer(4, 9); ++i) {
    const float ink = static_cast<float>(rng.uniform(0.05, 0.4));
    const int x = rng.integer(40, W - 300), y = rng.integer(60, H - 60);
    if (rng.chance(0.5)) {
      drawText(img, randomWords(rng, rng.integer(1, 4)), {x, y}, cv::FONT_HERSHEY_SCRIPT_SIMPLEX, rng.uniform(0.8, 1.5),
               2, ink);
    } else if (rng.chance(0.5)) {
      const int w = rng.integer(60, 200), h = rng.integer(40, 120);
      drawLine(img, cv::Point2f(x, y), cv::Point2f(x + w, y), 3, ink);
      drawLine(img, cv::Point2f(x + w, y), cv::Point2f(x + w, y + h), 3, ink);
      drawLine(img, cv::Point2f(x + w, y + h), cv::Point2f(x, y + h), 3, ink);
      drawLine(img, cv::Point2f(x, y + h), cv::Point2f(x, y), 3, ink);
      drawText(img, randomHeading(rng), {x + 8, y + h / 2 + 8}, cv::FONT_HERSHEY_SCRIPT_SIMPLEX, 0.8, 2, ink);
    } else {  // a plotted curve with axes
      drawLine(img, cv::Point2f(x, y), cv::Point2f(x, y - 150 < 0 ? 5 : y - 150), 3, ink);
      drawLine(img, cv::Point2f(x, y), cv::Point2f(x + 220, y), 3, ink);
      cv::Point2f prev(x, y - 10);
      for (int k = 1; k <= 20; ++k) {
        const cv::Point2f p(x + k * 11.f,
                            y - 10 - 110.f * static_cast<float>(std::pow(k / 20.0, rng.uniform(0.5, 2.5))));
        drawLine(img, prev, p, 3, ink);
        prev = p;
      }
    }
  }
  bevel(img, cv::Rect(0, 0, W, H), 12, 0.8f, 0.45f);
  return {img, false};
}

PaintedTexture paintBooks(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 1024, rows = 5, board = 22;
  cv::Mat img = canvas(W, H, 0.08f);  // dark back of the shelf
  const float wood = static_cast<float>(rng.uniform(0.35, 0.6));
  const int row_h = H / rows;
  for (int r = 0; r < rows; ++r) {
    const int y0 = r * row_h, floor_y = y0 + row_h - board;
    int x = rng.integer(2, 20);
    while (x < W - 10) {
      if (rng.chance(0.06)) {  // a gap or a lying stack
        x += rng.integer(20, 80);
        continue;
      }
      const int w = std::min(rng.integer(12, 42), W - 4 - x);
      const int h = static_cast<int>((row_h - board - 10) * rng.uniform(0.6, 0.97));
      const float v = static_cast<float>(rng.uniform(0.08, 0.9));
      const cv::Rect spine(x, floor_y - h, w, h);
      fillRect(img, spine, v);
      cv::Mat roi = img(spine & cv::Rect(0, 0, W, H));
      addValueNoise(roi, hashOf(seed, r, x), 2, 8, 0.03f);
      const float ink = v > 0.5f ? 0.08f : 0.9f;
      if (rng.chance(0.6)) {
        fillRect(img, cv::Rect(x, floor_y - h + h / 8, w, 4), ink, 0.8f);
        fillRect(img, cv::Rect(x, floor_y - h / 6, w, 4), ink, 0.8f);
      }
      if (w >= 16)
        drawVerticalText(img, randomWords(rng, 2), cv::Rect(x + 2, floor_y - h + h / 5, w - 4, h * 3 / 5),
                         cv::FONT_HERSHEY_PLAIN, 0.9, 1, ink);
      fillRect(img, cv::Rect(x + w - 1, floor_y - h, 1, h), 0.05f, 0.6f);  // gap shadow
      x += w + (rng.chance(0.2) ? 2 : 0);
    }
    fillRect(img, cv::Rect(0, floor_y, W, board), wood);
    fillRect(img, cv::Rect(0, floor_y, W, 3), wood + 0.15f);
  }
  addFbm(img, hashOf(seed, 9), 128, 2, 0.02f, 0.5);
  return {img, false};
}

PaintedTexture paintDoor(uint64_t seed) {
  Rng rng(seed);
  const int W = 512, H = 1024;
  const bool painted = rng.chance(0.5);
  cv::Mat img = canvas(W, H, painted ? static_cast<float>(rng.uniform(0.55, 0.85)) : 0.f);
  if (!painted) {
    PaintedTexture wood = paintWoodPanel(hashOf(seed, 1));
    cv::Mat tiled;
    cv::repeat(wood.image, 2, 1, tiled);
    tiled(cv::Rect(0, 0, W, H)).copyTo(img);
  }
  addFbm(img, hashOf(seed, 2), 256, 4, 0.015f, 0.6);
  const int panels = rng.integer(1, 3);
  const int m = 60;
  const int ph = (H - 2 * m - (panels - 1) * 40 - 120) / panels;
  for (int i = 0; i < panels; ++i) {
    const cv::Rect r(m, m + i * (ph + 40) + (i > 0 ? 120 : 0), W - 2 * m, ph);
    bevel(img, r, 8, 0.95f, 0.2f);
  }
  // Lever handle and lock, kick plate, sometimes a sign with a room number.
  const float metal = 0.75f;
  fillCircle(img, {W - 60.f, H * 0.52f}, 14.f, metal);
  fillRect(img, cv::Rect(W - 150, static_cast<int>(H * 0.52f) - 8, 95, 16), metal);
  fillRect(img, cv::Rect(W - 150, static_cast<int>(H * 0.52f) + 7, 95, 3), 0.2f, 0.6f);
  fillCircle(img, {W - 60.f, H * 0.58f}, 8.f, 0.3f);
  if (rng.chance(0.6)) {
    fillRect(img, cv::Rect(0, H - 110, W, 100), 0.7f);
    addFbm(img, hashOf(seed, 3), 64, 1, 0.04f, 0.3, 32.0);
  }
  if (rng.chance(0.7)) {
    const cv::Rect sign(W / 2 - 90, 250, 180, 70);
    fillRect(img, sign, rng.chance(0.5) ? 0.92f : 0.1f);
    drawText(img, randomHeading(rng).substr(0, 5), {sign.x + 14, sign.y + 48}, cv::FONT_HERSHEY_DUPLEX, 1.1, 2,
             img.at<float>(sign.y + 2, sign.x + 2) > 0.5f ? 0.08f : 0.9f);
  }
  bevel(img, cv::Rect(0, 0, W, H), 10, 0.9f, 0.25f);
  return {img, false};
}

PaintedTexture paintCabinet(uint64_t seed) {
  Rng rng(seed);
  const int W = 512, H = 512;
  PaintedTexture base = paintWoodPanel(hashOf(seed, 1));
  cv::Mat img = base.image.clone();
  if (rng.chance(0.4)) img = canvas(W, H, static_cast<float>(rng.uniform(0.6, 0.85)));
  const float gap = 0.08f, handle = static_cast<float>(rng.uniform(0.15, 0.8));
  if (rng.chance(0.5)) {  // two doors
    fillRect(img, cv::Rect(W / 2 - 2, 0, 4, H), gap);
    fillRect(img, cv::Rect(W / 2 - 30, H / 3, 8, 90), handle);
    fillRect(img, cv::Rect(W / 2 + 22, H / 3, 8, 90), handle);
  } else {  // drawers
    const int n = rng.integer(3, 5);
    for (int i = 1; i < n; ++i) fillRect(img, cv::Rect(0, i * H / n - 2, W, 4), gap);
    for (int i = 0; i < n; ++i) fillRect(img, cv::Rect(W / 2 - 50, i * H / n + H / (2 * n) - 5, 100, 10), handle);
  }
  if (rng.chance(0.5)) {  // a label
    fillRect(img, cv::Rect(30, 20, 120, 40), 0.92f);
    drawText(img, randomHeading(rng).substr(0, 4), {38, 50}, cv::FONT_HERSHEY_SIMPLEX, 0.8, 2, 0.05f);
  }
  bevel(img, cv::Rect(0, 0, W, H), 6, 0.9f, 0.2f);
  return {img, false};
}

PaintedTexture paintFacade(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 1024, bays = 4, storeys = 4;
  const int bw = W / bays, sh = H / storeys;
  // Wall material at facade scale (texels of about 1.2 cm): a quarter-size copy of brick or concrete, tiled.
  cv::Mat wall = rng.chance(0.5) ? paintConcrete(hashOf(seed, 1)).image : paintBrick(hashOf(seed, 2)).image;
  cv::resize(wall, wall, cv::Size(W / 4, H / 4), 0, 0, cv::INTER_AREA);
  cv::Mat img;
  cv::repeat(wall, 4, 4, img);
  img = img * rng.uniform(0.85, 1.25);
  const int win_w = static_cast<int>(bw * rng.uniform(0.45, 0.7)),
            win_h = static_cast<int>(sh * rng.uniform(0.45, 0.65));
  for (int s = 0; s < storeys; ++s) {
    fillRect(img, cv::Rect(0, s * sh, W, 8), 0.75f, 0.7f);  // floor slab band
    for (int b = 0; b < bays; ++b) {
      const cv::Rect win(b * bw + (bw - win_w) / 2, s * sh + (sh - win_h) / 2, win_w, win_h);
      gradientRect(img, win, static_cast<float>(rng.uniform(0.1, 0.45)), static_cast<float>(rng.uniform(0.05, 0.3)));
      cv::Mat glass = img(win);
      addFbm(glass, hashOf(seed, s, b), win_w / 2.0, 4, 0.06f, 0.8);  // reflections
      const int kind = rng.integer(0, 3);
      if (kind == 0) {  // blinds
        for (int y = win.y; y < win.y + win.height; y += 6)
          fillRect(img, cv::Rect(win.x, y, win.width, 3), 0.75f, 0.8f);
      } else if (kind == 1) {  // curtains
        fillRect(img, cv::Rect(win.x, win.y, win.width / 4, win.height), 0.6f, 0.9f);
        fillRect(img, cv::Rect(win.x + win.width * 3 / 4, win.y, win.width / 4, win.height), 0.6f, 0.9f);
      }
      const float frame = static_cast<float>(rng.uniform(0.1, 0.9));
      fillRect(img, cv::Rect(win.x - 5, win.y - 5, win.width + 10, 6), frame);
      fillRect(img, cv::Rect(win.x - 5, win.y + win.height, win.width + 10, 10), 0.85f);  // sill
      fillRect(img, cv::Rect(win.x - 5, win.y, 6, win.height), frame);
      fillRect(img, cv::Rect(win.x + win.width - 1, win.y, 6, win.height), frame);
      fillRect(img, cv::Rect(win.x + win.width / 2 - 2, win.y, 5, win.height), frame);
      fillRect(img, cv::Rect(win.x, win.y + win.height * 2 / 5, win.width, 5), frame);
    }
  }
  return {img, true};
}

PaintedTexture paintPerson(uint64_t seed) {
  Rng rng(seed);
  const int W = 256, H = 512;
  cv::Mat img = canvas(W, H, 0.f);
  const float skin = static_cast<float>(rng.uniform(0.35, 0.75));
  const float shirt = static_cast<float>(rng.uniform(0.1, 0.9));
  const float trousers = static_cast<float>(rng.uniform(0.05, 0.4));
  const int head = H * 13 / 100, waist = H * 48 / 100, feet = H * 95 / 100;
  fillRect(img, cv::Rect(0, 0, W, head), skin);
  fillRect(img, cv::Rect(0, 0, W, head / 3), static_cast<float>(rng.uniform(0.03, 0.5)));  // hair
  fillRect(img, cv::Rect(0, head, W, waist - head), shirt);
  if (rng.chance(0.4)) {
    for (int y = head; y < waist; y += 24)
      fillRect(img, cv::Rect(0, y, W, 10), shirt > 0.5f ? shirt - 0.3f : shirt + 0.3f);
  }
  fillRect(img, cv::Rect(0, head, W / 6, waist - head + 40), shirt * 0.8f);  // arms at the sides
  fillRect(img, cv::Rect(W - W / 6, head, W / 6, waist - head + 40), shirt * 0.8f);
  fillRect(img, cv::Rect(0, waist, W, feet - waist), trousers);
  fillRect(img, cv::Rect(W / 2 - 3, waist + 40, 6, feet - waist - 40), trousers * 0.5f);
  fillRect(img, cv::Rect(0, feet, W, H - feet), 0.06f);
  addFbm(img, hashOf(seed, 1), 64, 2, 0.04f, 0.5);
  return {img, false};
}

PaintedTexture paintTexture(TextureKind kind, uint64_t seed) {
  switch (kind) {
    case TextureKind::Plaster: return paintPlaster(seed);
    case TextureKind::Concrete: return paintConcrete(seed);
    case TextureKind::Brick: return paintBrick(seed);
    case TextureKind::WoodPlanks: return paintWoodPlanks(seed);
    case TextureKind::WoodPanel: return paintWoodPanel(seed);
    case TextureKind::Tiles: return paintTiles(seed);
    case TextureKind::Linoleum: return paintLinoleum(seed);
    case TextureKind::Carpet: return paintCarpet(seed);
    case TextureKind::Fabric: return paintFabric(seed);
    case TextureKind::Metal: return paintMetal(seed);
    case TextureKind::CeilingTiles: return paintCeilingTiles(seed);
    case TextureKind::Poster: return paintPoster(seed);
    case TextureKind::NoticeBoard: return paintNoticeBoard(seed);
    case TextureKind::Whiteboard: return paintWhiteboard(seed);
    case TextureKind::Books: return paintBooks(seed);
    case TextureKind::Door: return paintDoor(seed);
    case TextureKind::Cabinet: return paintCabinet(seed);
    case TextureKind::Facade: return paintFacade(seed);
    case TextureKind::Paving: return paintPaving(seed);
    case TextureKind::Grass: return paintGrass(seed);
    case TextureKind::Foliage: return paintFoliage(seed);
    case TextureKind::Bark: return paintBark(seed);
    case TextureKind::Asphalt: return paintAsphalt(seed);
    case TextureKind::Person: return paintPerson(seed);
    case TextureKind::Radiator: return paintRadiator(seed);
    case TextureKind::Count: break;
  }
  return paintPlaster(seed);
}

}  // namespace mcslam::sim
