#include "rascal_perception/PhotoSegmenter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <opencv2/imgproc.hpp>

namespace rascal_perception {

std::vector<std::string> flagNames(unsigned flags) {
  static const std::pair<unsigned, const char*> kNames[] = {{kProbablySeveral, "probably_several"},
                                                            {kTouchesBorder, "touches_border"},
                                                            {kLowContrast, "low_contrast"},
                                                            {kNoScale, "no_scale"}};
  std::vector<std::string> names;
  for (const auto& [bit, name] : kNames) {
    if (flags & bit) names.emplace_back(name);
  }
  return names;
}

namespace {
constexpr int kWorkSide = 640;  // [px] contrast resolution, see contrast()
constexpr double kCoarseCells = 160.0;  // cells along the longer side of the background grid
constexpr double kOutlineCells = 1.5;   // a blob centred closer to the cloth's outline is off it
constexpr double kSheetSolidity = 0.9;  // a cloth's region fills at least this much of its hull
// [CIELab a*b* units] two surfaces whose mean chromaticities differ by more are two materials
// (a dark cloth on a sandy floor: 24-26 in the three photos that show one), not one cloth in
// two lights (at most 5 where k-means split a cloth by its shading)
constexpr double kOtherMaterialChroma = 12.0;

/// a*b* distance of two mean colours of OpenCV's 8-bit Lab (a*, b* offset by 128; unit 1).
double chromaDistance(const cv::Scalar& x, const cv::Scalar& y) { return std::hypot(x[1] - y[1], x[2] - y[2]); }

/// Median of |m| over the pixels where `where` is set (every `step`-th row and column).
double medianAbs(const cv::Mat& m, const cv::Mat& where, int step) {
  std::vector<float> v;
  for (int y = 0; y < m.rows; y += step) {
    const float* p = m.ptr<float>(y);
    const uint8_t* w = where.ptr<uint8_t>(y);
    for (int x = 0; x < m.cols; x += step) {
      if (w[x]) v.push_back(std::fabs(p[x]));
    }
  }
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// Lightness difference of each pixel of `lab` (CV_32FC3) to `bg` (same size), and its a*b*
/// distance to the cloth's a*b* as a shadow would show it: a shadow dims the light, which
/// shrinks a*b* towards grey with L*, so the cloth's a*b* is scaled by min(1, L / L_bg) first.
void differences(const cv::Mat& lab, const cv::Mat& bg, cv::Mat& dl, cv::Mat& dab) {
  // one pass over the pixels: this runs at the working resolution for every surface, and a
  // chain of whole-image OpenCV operations on float images cost three times as much
  CV_Assert(lab.type() == CV_32FC3 && bg.type() == CV_32FC3 && lab.size() == bg.size());
  dl.create(lab.size(), CV_32F);
  dab.create(lab.size(), CV_32F);
  for (int y = 0; y < lab.rows; ++y) {
    const cv::Vec3f* p = lab.ptr<cv::Vec3f>(y);
    const cv::Vec3f* b = bg.ptr<cv::Vec3f>(y);
    float* l = dl.ptr<float>(y);
    float* c = dab.ptr<float>(y);
    for (int x = 0; x < lab.cols; ++x) {
      l[x] = p[x][0] - b[x][0];
      const float dim = std::min(p[x][0] / std::max(b[x][0], 1.0f), 1.0f);
      const float da = p[x][1] - 128.0f - (b[x][1] - 128.0f) * dim;
      const float db = p[x][2] - 128.0f - (b[x][2] - 128.0f) * dim;
      // and a*b* of a dim pixel is noise (camera noise and JPEG over a few grey levels):
      // weigh its distance by how much light it got, so deep shadows do not look coloured
      c[x] = std::sqrt(da * da + db * db) * dim;
    }
  }
}

/// Contrast of each pixel to one surface, in units of that surface's spread (`sl` for L*,
/// `sab` for a*b*): lighter than the surface, or another chromaticity. Darker with the
/// surface's (dimmed) chromaticity is a shadow, so darker counts only where the chromaticity
/// also differs (dark paint, brown clay on grey cloth).
cv::Mat surfaceScore(const cv::Mat& dl, const cv::Mat& dab, double sl, double sab) {
  cv::Mat score(dl.size(), CV_32F);
  const float il = static_cast<float>(1.0 / sl), iab = static_cast<float>(1.0 / sab);
  for (int y = 0; y < dl.rows; ++y) {
    const float* l = dl.ptr<float>(y);
    const float* c = dab.ptr<float>(y);
    float* o = score.ptr<float>(y);
    for (int x = 0; x < dl.cols; ++x) {
      const float lighter = l[x] * il, colour = c[x] * iab;
      const float darker = colour < 2.0f ? 0.0f : -lighter;
      o[x] = std::max(std::max(lighter, colour), darker);
    }
  }
  return score;
}
}  // namespace

namespace {
/// The cloth's outline on the coarse grid: the convex hull of the largest connected piece of
/// its region (holes filled) once thin links are opened away: a chair's frame or a strip of
/// the same colour touching its edge is not part of the sheet. A cloth is one convex sheet, so
/// the opening grows until the piece fills its hull; empty if it never does (no outline is
/// better than a wrong one).
std::vector<cv::Point> clothHull(const cv::Mat& cloth_region) {
  // every hole filled first: a shadow or a hotspot across the sheet is a hole in the cloth's
  // colour, not in the sheet, and the sherds around it would leave only thin links to open
  std::vector<std::vector<cv::Point>> pieces;
  cv::findContours(cloth_region.clone(), pieces, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::Mat solid = cv::Mat::zeros(cloth_region.size(), CV_8U);
  cv::drawContours(solid, pieces, -1, cv::Scalar(255), cv::FILLED);
  for (const int k : {5, 9, 13, 17}) {
    cv::Mat body, cc, stats, centroids;
    cv::morphologyEx(solid, body, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    const int n = cv::connectedComponentsWithStats(body, cc, stats, centroids, 4, CV_32S);
    int best = 0;
    for (int i = 1; i < n; ++i) {
      if (best == 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = i;
    }
    if (best == 0) return {};
    std::vector<std::vector<cv::Point>> outlines;
    cv::findContours(cc == best, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    if (outlines.empty()) return {};
    std::vector<cv::Point> hull;
    cv::convexHull(outlines.front(), hull);
    if (stats.at<int>(best, cv::CC_STAT_AREA) >= kSheetSolidity * cv::contourArea(hull)) return hull;
  }
  return {};
}

/// A Gaussian blur of standard deviation `sigma` approximated by three box filters: the same
/// smoothing at a cost independent of sigma (the background's sigma is 20 cells).
void smooth(const cv::Mat& in, cv::Mat& out, double sigma) {
  const int w = std::max(1, cvRound(std::sqrt(4.0 * sigma * sigma + 1.0))) | 1;
  cv::boxFilter(in, out, -1, cv::Size(w, w));
  cv::boxFilter(out, out, -1, cv::Size(w, w));
  cv::boxFilter(out, out, -1, cv::Size(w, w));
}

/// A smooth background from the pixels of `small` where `near` is set, refined `rounds` times
/// from the pixels close to its own estimate (so it follows uneven light): normalised
/// convolution, so sherds leave holes that their surroundings fill in. `support`: how much of
/// the surface lies around each cell (0 far from it); `region`: the cells it covers, holes filled.
void smoothBackground(const cv::Mat& small, cv::Mat& near, int rounds, double reach, const cv::Mat& spread_over,
                      double min_piece, cv::Mat& bg, cv::Mat& support, cv::Mat* region = nullptr) {
  const double sigma = std::max(small.cols, small.rows) / 8.0;
  for (int it = 0; it < rounds; ++it) {
    cv::erode(near, near, cv::Mat());
    cv::Mat w, w3, num, s3;
    near.convertTo(w, CV_32F, 1.0 / 255.0);
    cv::merge(std::vector<cv::Mat>{w, w, w}, w3);
    smooth(small.mul(w3), num, sigma);
    smooth(w, support, sigma);
    cv::merge(std::vector<cv::Mat>{support, support, support}, s3);
    cv::divide(num, cv::max(s3, 1e-4), bg);
    cv::Mat dl, dab;
    differences(small, bg, dl, dab);
    const double sl = 1.4826 * medianAbs(dl, spread_over, 1) + 1.0;
    const double sab = 1.4826 * medianAbs(dab, spread_over, 1) + 1.0;
    near = (cv::abs(dl) < std::max(reach * sl, 8.0)) & (dab < std::max(reach * sab, 6.0)) & (support > 0.02f);
  }
  // where the surface itself lies: its pixels smoothed at a finer scale (a strip of floor
  // between a mat and the photo's edge is floor, though the mat dominates around it)
  // only its large pieces (a sherd of its colour elsewhere is not it), with their holes
  // filled: a sherd lying on it is on it, whatever its colour
  std::vector<std::vector<cv::Point>> outlines, large;
  cv::findContours(near, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  for (auto& o : outlines) {
    if (cv::contourArea(o) >= min_piece * near.total()) large.push_back(std::move(o));
  }
  cv::Mat filled = cv::Mat::zeros(near.size(), CV_8U), w;
  cv::drawContours(filled, large, -1, cv::Scalar(255), cv::FILLED);
  // ... but only sherd-sized holes: a surface-sized hole is another surface (a sheet on the
  // floor is a hole in the floor)
  cv::Mat holes = filled & ~near, cc, stats, centroids;
  const int n = cv::connectedComponentsWithStats(holes, cc, stats, centroids, 4, CV_32S);
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) >= min_piece * near.total()) filled.setTo(0, cc == i);
  }
  filled.convertTo(w, CV_32F, 1.0 / 255.0);
  smooth(w, support, sigma / 4);
  if (region) *region = filled;
}
}  // namespace

cv::Mat PhotoSegmenter::contrast(const cv::Mat& full, const cv::Mat& background, PhotoResult& r) const {
  // Contrast is computed on at most kWorkSide pixels along the longer side and interpolated
  // back: it is smooth at the scale of a pixel, and this is most of the time per photo.
  cv::Mat rgb = full;
  const int longer = std::max(full.cols, full.rows);
  if (longer > kWorkSide) {
    const double k = static_cast<double>(kWorkSide) / longer;
    cv::resize(full, rgb, cv::Size(cvRound(full.cols * k), cvRound(full.rows * k)), 0, 0, cv::INTER_AREA);
  }
  // Lab: L* and a*b* separate light from colour, and distances in it are roughly perceptual
  cv::Mat lab;
  cv::cvtColor(rgb, lab, cv::COLOR_RGB2Lab);
  lab.convertTo(lab, CV_32F);
  // The background on a coarse grid (about 160 cells across): cheap, and sherds smaller than
  // the smoothing scale do not pull it.
  const int f = std::max(1, cvRound(std::max(rgb.cols, rgb.rows) / kCoarseCells));
  const cv::Size coarse(std::max(1, rgb.cols / f), std::max(1, rgb.rows / f));
  cv::Mat small;
  cv::resize(lab, small, coarse, 0, 0, cv::INTER_AREA);
  // One smooth background per surface: the cloth, and where the photo's rim is mostly
  // something else (floor, table, frame), that too; a pixel's contrast is to the nearer one.
  std::vector<cv::Mat> bgs, supports;
  cv::Mat quiet_cloth;  // full resolution: the cells the cloth's estimate was made from
  if (!background.empty()) {  // an empty-background photo is the model itself
    cv::Mat empty;
    cv::cvtColor(background, empty, cv::COLOR_RGB2Lab);
    empty.convertTo(empty, CV_32F);
    cv::resize(empty, empty, rgb.size(), 0, 0, cv::INTER_AREA);  // compared pixel by pixel
    bgs.push_back(empty);
    supports.push_back(cv::Mat(coarse, CV_32F, cv::Scalar(1)));
  } else {
    // the cloth: the largest of a few k-means colours (seeded; others' RNG untouched) as a
    // start, then the smooth estimate
    // The colours are found on every other cell each way, and every cell is then labelled by
    // its nearest colour: the clustering was a quarter of the time per photo, and a surface or
    // a sherd large enough to matter here covers many cells of the quarter.
    cv::Mat labels, centres;
    const int k = std::max(2, options_.clusters);
    {
      cv::Mat sampled;
      cv::resize(small, sampled, cv::Size((coarse.width + 1) / 2, (coarse.height + 1) / 2), 0, 0, cv::INTER_NEAREST);
      cv::Mat samples = sampled.reshape(1, static_cast<int>(sampled.total())), sampled_labels;
      const uint64_t saved_rng = cv::theRNG().state;
      cv::theRNG().state = 1;
      cv::kmeans(samples, k, sampled_labels,
                 cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 0.5), 1, cv::KMEANS_PP_CENTERS,
                 centres);
      cv::theRNG().state = saved_rng;
    }
    labels.create(coarse, CV_32S);
    for (int y = 0; y < coarse.height; ++y) {
      const cv::Vec3f* p = small.ptr<cv::Vec3f>(y);
      int* l = labels.ptr<int>(y);
      for (int x = 0; x < coarse.width; ++x) {
        float nearest = std::numeric_limits<float>::max();
        for (int c = 0; c < centres.rows; ++c) {
          const float* m = centres.ptr<float>(c);
          const float d0 = p[x][0] - m[0], d1 = p[x][1] - m[1], d2 = p[x][2] - m[2];
          const float d = d0 * d0 + d1 * d1 + d2 * d2;
          if (d < nearest) {
            nearest = d;
            l[x] = c;
          }
        }
      }
    }
    // the cloth is the colour of the largest connected piece, its cells counted with less
    // weight towards the rim: a photo is framed on the cloth, sherds of the table's colour are
    // many small pieces, and a table around a mat is at the rim
    cv::Mat weight(coarse, CV_64F);
    for (int y = 0; y < coarse.height; ++y) {
      const double v = (y + 0.5) / coarse.height * 2.0 - 1.0;
      for (int x = 0; x < coarse.width; ++x) {
        const double u = (x + 0.5) / coarse.width * 2.0 - 1.0;
        weight.at<double>(y, x) = std::max(0.0, 1.0 - 0.5 * (u * u + v * v));
      }
    }
    int largest = 0;
    double most_present = -1.0;
    for (int c = 0; c < k; ++c) {
      cv::Mat cc;
      const int n = cv::connectedComponents(labels == c, cc, 4, CV_32S);
      std::vector<double> presence(n, 0.0);
      for (int y = 0; y < coarse.height; ++y) {
        for (int x = 0; x < coarse.width; ++x) presence[cc.at<int>(y, x)] += weight.at<double>(y, x);
      }
      for (int i = 1; i < n; ++i) {
        if (presence[i] > most_present) {
          most_present = presence[i];
          largest = c;
        }
      }
    }
    // one large connected piece of another colour, larger than any sherd, is a second
    // surface (a mat on a table): sherds are many pieces, a surface is one
    std::vector<cv::Mat> pieces(k);
    for (int c = 0; c < k; ++c) {
      if (c == largest) continue;
      cv::Mat piece = labels == c, cc, stats, centroids;
      cv::erode(piece, piece, cv::Mat());
      const int m = cv::connectedComponentsWithStats(piece, cc, stats, centroids, 4, CV_32S);
      for (int i = 1; i < m; ++i) {
        if (stats.at<int>(i, cv::CC_STAT_AREA) > options_.surface_fraction * small.total()) pieces[c] = cc == i;
      }
    }
    const bool two_surfaces = std::any_of(pieces.begin(), pieces.end(), [](const cv::Mat& p) { return !p.empty(); });
    // the cloth's spread over the whole photo (loose while the estimate is still rough),
    // unless the photo is two surfaces, whose spread together says nothing of either
    cv::Mat bg, support, cloth_region, near = labels == largest;
    smoothBackground(small, near, 3, 2.5, two_surfaces ? near.clone() : cv::Mat(coarse, CV_8U, cv::Scalar(1)),
                     options_.surface_fraction / 3, bg, support, &cloth_region);
    cv::resize(near, quiet_cloth, rgb.size(), 0, 0, cv::INTER_NEAREST);
    bgs.push_back(bg);
    supports.push_back(support);
    // Trust: the rim should be mostly cloth (sherds lie inside the photo). Where it is not,
    // what it shows instead (floor, a table, a frame) is a second surface.
    cv::Mat dl, dab;
    differences(small, bg, dl, dab);
    const double sl = 1.4826 * medianAbs(dl, labels == largest, 1) + 1.0;
    const double sab = 1.4826 * medianAbs(dab, labels == largest, 1) + 1.0;
    const cv::Mat cloth = (cv::abs(dl) < std::max(3.0 * sl, 8.0)) & (dab < std::max(3.0 * sab, 6.0));
    const int band = std::max(1, std::min(coarse.width, coarse.height) / 25);
    cv::Mat rim(coarse, CV_8U, cv::Scalar(255));
    rim(cv::Rect(band, band, coarse.width - 2 * band, coarse.height - 2 * band)).setTo(0);
    const double on_cloth = static_cast<double>(cv::countNonZero(cloth & rim)) / cv::countNonZero(rim);
    if (on_cloth < 0.6) {
      r.background_trusted = false;
      char line[160];
      std::snprintf(line, sizeof line, "background doubtful: only %.0f %% of the photo's rim looks like the cloth",
                    100.0 * on_cloth);
      r.warnings.emplace_back(line);
    }
    // Other surfaces: the large pieces above, and a colour holding a tenth of the rim where
    // the rim is not cloth (the floor, a frame)
    const cv::Mat other = rim & ~cloth;
    const double rim_cells = cv::countNonZero(rim);
    const std::vector<cv::Point> hull = clothHull(cloth_region);
    cv::Mat sheet = cv::Mat::zeros(coarse, CV_8U);  // inside the outline, shadows included
    if (hull.size() >= 3) cv::fillConvexPoly(sheet, hull, cv::Scalar(255));
    bool around = false;  // some surface lies around the cloth rather than on it
    const cv::Scalar cloth_colour = cv::mean(small, labels == largest);
    for (int c = 0; c < k; ++c) {
      if (c == largest) continue;
      const bool on_rim = on_cloth < 0.8 && cv::countNonZero(other & (labels == c)) > 0.1 * rim_cells;
      if (!on_rim && pieces[c].empty()) continue;
      cv::Mat bg2, support2, near2 = pieces[c].empty() ? cv::Mat((labels == c) & ~cloth) : pieces[c];
      // its spread over its own first pixels: the whole photo is mostly cloth
      const cv::Mat first = near2.clone();
      smoothBackground(small, near2, 2, 4.0, first, options_.surface_fraction / 3, bg2, support2);
      // Where the rim is mostly not cloth, the cloth is a sheet inside the photo. A surface of
      // another material on the rim (another chromaticity, not the cloth in other light: the
      // floor, a table) lies around the sheet, not under anything inside it: a pale sherd the
      // colour of the floor is still a sherd (where the cloth lies: its cells, holes filled).
      if (on_rim && !r.background_trusted && hull.size() >= 3 &&
          chromaDistance(cv::mean(small, first), cloth_colour) > kOtherMaterialChroma) {
        support2.setTo(0, cloth_region | sheet);
        around = true;
      }
      bgs.push_back(bg2);
      supports.push_back(support2);
    }
    if (around) {  // in the full photo's pixels
      const double sx = static_cast<double>(full.cols) / coarse.width, sy = static_cast<double>(full.rows) / coarse.height;
      for (const cv::Point& p : hull) r.cloth_outline.emplace_back(cvRound((p.x + 0.5) * sx), cvRound((p.y + 0.5) * sy));
    }
  }
  // per surface: lightness and shadow-aware chroma difference at working resolution; the unit
  // is that surface's own spread (texture, lint, noise) over the pixels close to it
  std::vector<cv::Mat> scores, full_supports;
  for (size_t i = 0; i < bgs.size(); ++i) {
    cv::Mat bg_full, dl, dab;
    cv::resize(bgs[i], bg_full, rgb.size(), 0, 0, cv::INTER_LINEAR);
    differences(lab, bg_full, dl, dab);
    const cv::Mat quiet = i == 0 && !quiet_cloth.empty() ? quiet_cloth : cv::Mat((cv::abs(dl) < 12.0) & (dab < 8.0));
    const int step = std::max(1, static_cast<int>(std::sqrt(rgb.total() / 60000.0)));
    const double sl = std::max(options_.min_contrast_l, 1.4826 * medianAbs(dl, quiet, step));
    const double sab = std::max(options_.min_contrast_ab, 1.4826 * medianAbs(dab, quiet, step));
    cv::Mat s_i = surfaceScore(dl, dab, sl, sab);
    cv::Mat support;
    cv::resize(supports[i], support, rgb.size(), 0, 0, cv::INTER_LINEAR);
    scores.push_back(s_i);
    full_supports.push_back(support);
  }
  // a pixel is compared with the surface it lies on (the one most present around it), and
  // with any other nearly as present (near the edge between two)
  cv::Mat score;
  if (scores.size() == 1) {
    score = scores[0];
  } else {
    // the cloth is what the photo is of: where no other surface is present, a pixel lies on it,
    // even inside a large hole of its own presence (a hotspot or a shadowed half of the cloth
    // that its smooth estimate left out is still cloth, not 'no surface')
    cv::Mat others = full_supports[1].clone();
    for (size_t i = 2; i < scores.size(); ++i) others = cv::max(others, full_supports[i]);
    cv::Mat absent = 1.0 - others;
    full_supports[0] = cv::max(full_supports[0], absent);
    cv::Mat most = full_supports[0].clone();
    for (size_t i = 1; i < scores.size(); ++i) most = cv::max(most, full_supports[i]);
    score = cv::Mat(rgb.size(), CV_32F, cv::Scalar(1e6));
    for (size_t i = 0; i < scores.size(); ++i) {
      cv::Mat s_i = scores[i];
      s_i.setTo(1e6, full_supports[i] < 0.25 * most);
      score = cv::min(score, s_i);
    }
  }
  if (score.size() != full.size()) cv::resize(score, score, full.size(), 0, 0, cv::INTER_LINEAR);
  return score;
}

namespace {
// Seam splitting (photos only; the station detector has depth). Measured on the three real
// photos: the two edge-to-edge pairs (img114, img071) score 42 and 45 grey levels of black-hat
// along their crack and split into halves of solidity 0.95-0.96; no single sherd gives two
// halves both above 0.92.
constexpr double kSeamSolidityBelow = 0.9;   // only blobs this far from convex are looked at
constexpr double kSeamMinDefect = 0.15;      // deepest concavity, x sqrt(area)
constexpr double kSeamMinLength = 0.3;       // cut length, x sqrt(area)
constexpr double kSeamMinContrast = 35.0;    // mean black-hat along the cut, grey levels
constexpr double kSeamMinPart = 0.2;         // each half, x the blob's area
constexpr double kSeamHalfSolidity = 0.93;   // each half must be this convex
// A cut that joins two concavities (the notches where two outlines meet, one on each side of
// the seam) is the shape of a touching pair itself, so it is looked for in blobs nearer convex
// and with shallower notches. A blob that convex looks like one sherd, so its cut must be
// darker: img149's camera original, a pair laid edge to edge (solidity 0.90, notches 0.06 and
// 0.15), scores 67 grey levels; the edge of a blue band painted on a white majolica sherd, 40.
constexpr double kPairSolidityBelow = 0.95;
constexpr double kPairMinDefect = 0.04;      // each concavity, x sqrt(area)
constexpr double kPairConvexContrast = 1.5;  // x kSeamMinContrast, blobs above kSeamSolidityBelow
// The mask's closing rounds a notch, so its deepest point lies a few px beside where the seam
// meets the outline: each end of a notch-to-notch cut is tried this many outline px around it.
constexpr int kNotchSlack = 4;
constexpr double kSeamShowsCloth = 0.1;  // see showsTheCloth

double solidity(const std::vector<cv::Point>& c) {
  std::vector<cv::Point> hull;
  cv::convexHull(c, hull);
  const double h = cv::contourArea(hull);
  return h > 0 ? cv::contourArea(c) / h : 1.0;
}

/// Concavities of an outline deeper than `min_depth` px, deepest first.
std::vector<cv::Vec4i> concavities(const std::vector<cv::Point>& contour, double min_depth) {
  std::vector<int> hull;
  cv::convexHull(contour, hull, false, false);
  std::vector<cv::Vec4i> defects;
  if (hull.size() < 3) return defects;
  std::sort(hull.begin(), hull.end());  // convexityDefects wants a monotonic hull
  try {
    cv::convexityDefects(contour, hull, defects);
  } catch (const cv::Exception&) {  // self-intersecting contour: no concavities used
    return {};
  }
  defects.erase(std::remove_if(defects.begin(), defects.end(),
                               [&](const cv::Vec4i& d) { return d[3] / 256.0 < min_depth; }),
                defects.end());
  std::sort(defects.begin(), defects.end(), [](const cv::Vec4i& x, const cv::Vec4i& y) { return x[3] > y[3]; });
  return defects;
}

/// The pixels of the straight cut p-q, one per px, less 3 at each end (they lie on the edge).
std::vector<cv::Point> pointsAlongCut(const cv::Point& p, const cv::Point& q) {
  const int n = static_cast<int>(cv::norm(q - p));
  std::vector<cv::Point> points;
  for (int i = 3; i <= n - 3; ++i) {
    const double t = static_cast<double>(i) / n;
    points.emplace_back(cvRound(p.x + t * (q.x - p.x)), cvRound(p.y + t * (q.y - p.y)));
  }
  return points;
}

/// Mean black-hat along the straight cut p-q, or -1 where the cut leaves the blob (`inside`,
/// its mask eroded, offset by `tl`) or is too short to judge.
double cutContrast(const cv::Point& p, const cv::Point& q, const cv::Mat& inside, const cv::Point& tl,
                   const cv::Mat& blackhat) {
  double sum = 0.0;
  int used = 0, outside = 0;
  for (const cv::Point& s : pointsAlongCut(p, q)) {
    if (!inside.at<uint8_t>(s - tl)) ++outside;
    sum += blackhat.at<uint8_t>(s);
    ++used;
  }
  if (used < 5 || outside > 0.05 * used) return -1.0;  // the cut must run through the blob
  return sum / used;
}

/// Median of `grey` over the pixels of `mask` (CV_8U, same size).
double medianGrey(const cv::Mat& grey, const cv::Mat& mask) {
  int histogram[256] = {0}, n = 0;
  for (int y = 0; y < grey.rows; ++y) {
    const uint8_t* g = grey.ptr<uint8_t>(y);
    const uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < grey.cols; ++x) {
      if (m[x]) ++histogram[g[x]], ++n;
    }
  }
  for (int v = 0, seen = 0; v < 256; ++v) {
    if (2 * (seen += histogram[v]) >= n) return v;
  }
  return 0.0;
}

/// Whether the cut p-q across blob `b` runs where two pieces part: the gap shows the cloth or
/// a shadow, so its median grey is no lighter than the cloth's around the blob plus a tenth
/// of the way to the sherd's own. A painted band, an incised line, a glaze's edge (the
/// notch-to-notch cuts' false seams on the photos' held-out transforms) lie on the sherd and
/// are lighter: 0.14-0.80 of the way; the pairs laid edge to edge, at most the cloth's grey.
bool showsTheCloth(const cv::Mat& grey, const Blob& b, const cv::Point& p, const cv::Point& q) {
  std::vector<uint8_t> along;
  for (const cv::Point& s : pointsAlongCut(p, q)) along.push_back(grey.at<uint8_t>(s));
  if (along.empty()) return false;
  std::nth_element(along.begin(), along.begin() + along.size() / 2, along.end());
  constexpr int kRing = 5;  // px around the blob: the cloth beside it
  const cv::Rect grown =
      (b.bounds + cv::Size(2 * kRing + 2, 2 * kRing + 2) - cv::Point(kRing + 1, kRing + 1)) & cv::Rect(cv::Point(), grey.size());
  cv::Mat blob = cv::Mat::zeros(grown.size(), CV_8U), ring, body;
  b.mask.copyTo(blob(b.bounds - grown.tl()));
  cv::dilate(blob, ring, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * kRing + 1, 2 * kRing + 1)));
  ring &= ~blob;
  cv::erode(blob, body, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * kRing + 1, 2 * kRing + 1)));
  const double cloth = medianGrey(grey(grown), ring), sherd = medianGrey(grey(grown), body);
  return along[along.size() / 2] <= cloth + kSeamShowsCloth * (sherd - cloth);
}
}  // namespace

void PhotoSegmenter::splitAtSeams(std::vector<Blob>& blobs, const cv::Mat& rgb) const {
  cv::Mat grey, blackhat;  // thin dark lines, computed only if some blob needs them
  std::vector<Blob> out;
  for (Blob& b : blobs) {
    const double area = cv::contourArea(b.contour);
    const double side = std::sqrt(area);
    const double solid = solidity(b.contour);
    std::vector<cv::Vec4i> notches;
    if (solid < kPairSolidityBelow) notches = concavities(b.contour, kPairMinDefect * side);
    const bool deep = !notches.empty() && solid < kSeamSolidityBelow && notches[0][3] / 256.0 >= kSeamMinDefect * side;
    if (!deep && notches.size() < 2) {
      out.push_back(std::move(b));
      continue;
    }
    if (blackhat.empty()) {
      cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
      cv::morphologyEx(grey, blackhat, cv::MORPH_BLACKHAT, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
    }
    cv::Mat inside;
    cv::erode(b.mask, inside, cv::Mat::ones(3, 3, CV_8U));
    // the darkest cut of each kind, relative to what that kind needs
    struct Cut {
      double score = 0.0;
      cv::Point p, q;
    };
    const auto darker = [&](Cut& best, const cv::Point& p, const cv::Point& q, double needs) {
      if (cv::norm(q - p) < kSeamMinLength * side) return;
      const double c = cutContrast(p, q, inside, b.bounds.tl(), blackhat) / needs;
      if (c > best.score) best = {c, p, q};
    };
    Cut from_deepest, notch_to_notch;
    if (deep) {  // from the deepest notch to wherever the outline runs darkest
      const cv::Point p = b.contour[notches[0][2]];
      for (size_t k = 0; k < b.contour.size(); k += 2) darker(from_deepest, p, b.contour[k], kSeamMinContrast);
    }
    const double pair_needs = kSeamMinContrast * (solid < kSeamSolidityBelow ? 1.0 : kPairConvexContrast);
    const int len = static_cast<int>(b.contour.size());
    const auto near = [&](int at, int offset) { return b.contour[((at + offset) % len + len) % len]; };
    for (size_t i = 0; i < notches.size(); ++i) {
      for (size_t j = i + 1; j < notches.size(); ++j) {
        for (int di = -kNotchSlack; di <= kNotchSlack; ++di) {
          for (int dj = -kNotchSlack; dj <= kNotchSlack; ++dj) {
            darker(notch_to_notch, near(notches[i][2], di), near(notches[j][2], dj), pair_needs);
          }
        }
      }
    }
    Cut chosen = from_deepest;
    if (notch_to_notch.score >= 1.0 && notch_to_notch.score > chosen.score &&
        showsTheCloth(grey, b, notch_to_notch.p, notch_to_notch.q)) {
      chosen = notch_to_notch;
    }
    std::vector<Blob> halves;
    if (chosen.score >= 1.0) {
      cv::Mat cut = b.mask.clone();
      cv::line(cut, chosen.p - b.bounds.tl(), chosen.q - b.bounds.tl(), cv::Scalar(0), 2);
      cv::Mat labels, stats, centroids;
      const int n = cv::connectedComponentsWithStats(cut, labels, stats, centroids, 4, CV_32S);
      for (int i = 1; i < n; ++i) {
        if (stats.at<int>(i, cv::CC_STAT_AREA) < kSeamMinPart * area) continue;
        Blob half = SherdSegmenter::blobOf(labels == i, b.bounds.tl());
        if (!half.contour.empty() && solidity(half.contour) >= kSeamHalfSolidity) halves.push_back(std::move(half));
      }
    }
    if (halves.size() == 2) {
      for (Blob& h : halves) out.push_back(std::move(h));
    } else {
      out.push_back(std::move(b));
    }
  }
  blobs = std::move(out);
}

namespace {
// A blob over this many times the median blob (with at least kManyBlobs blobs, so the median
// is a sherd's) is probably several sherds.
constexpr double kSeveralTypical = 4.0;
constexpr size_t kManyBlobs = 5;
// Such a blob with less than this of it above the strong contrast is mostly cloth that leaked
// in. Over the 20 photos and their transforms (bench/perception_robustness, set 1), the two
// leaks (img005 and img149_orig at gamma 1.5, a hotspot on a dark cloth) hold 0.22; the one
// other blob that large and below low_contrast, 0.46 (a white bag beside the board, no sherd).
constexpr double kLeakClear = 0.3;
constexpr double kLeakPartTypical = 0.25;  // x the median blob: the least a piece cut back to is

/// Clears foreground rows and columns near the border that are mostly foreground along their
/// whole length: a frame or mount around an edited photo, or the cloth's lit edge, never a row
/// of sherds (they lie apart on the cloth). Sherds touching the strip are kept.
void removeFrame(cv::Mat& fg, PhotoResult& r) {
  const int depth_x = std::max(2, fg.cols / 25), depth_y = std::max(2, fg.rows / 25);
  cv::Mat rows, cols;
  cv::reduce(fg, rows, 1, cv::REDUCE_AVG, CV_32F);  // one value per row
  cv::reduce(fg, cols, 0, cv::REDUCE_AVG, CV_32F);  // one value per column
  constexpr float kFull = 0.5f * 255.0f;
  int cleared = 0;
  auto strip = [&](const cv::Mat& profile, int n, int depth, bool is_row) {
    for (int side = 0; side < 2; ++side) {
      int last = -1;  // the innermost full line within `depth` of this side
      for (int k = 0; k < depth; ++k) {
        const int i = side ? n - 1 - k : k;
        if (profile.at<float>(is_row ? i : 0, is_row ? 0 : i) >= kFull) last = k;
      }
      for (int k = 0; k <= last; ++k) {
        const int i = side ? n - 1 - k : k;
        (is_row ? fg.row(i) : fg.col(i)).setTo(0);
      }
      cleared += last + 1;
    }
  };
  strip(rows, fg.rows, depth_y, true);
  strip(cols, fg.cols, depth_x, false);
  if (cleared > 0) r.warnings.emplace_back("a frame or strip along the photo's border was left out");
}
}  // namespace

namespace {
/// Closes pinholes and paint cracks (radius px), then opens away lint and scratches (twice that).
void cleanMask(cv::Mat& mask, int radius) {
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(4 * radius + 1, 4 * radius + 1)));
}

/// Where the cloth's estimate misses a hotspot or a gradient (a lamp on a dark cloth), the
/// cloth there is a little lighter than the estimate: weak contrast all over, which the
/// hysteresis joins to the sherds lying in it, one blob many sherds large and mostly weak.
/// Such a blob is cut back to its strong pixels (cleaned as the whole mask was): the sherds
/// in it stand out clearly, the leaked cloth does not. Returns the blobs in place of `b`, or
/// none when the strong pixels do not give a sherd-sized piece.
std::vector<Blob> cutBackToStrong(const Blob& b, const cv::Mat& strong, const SegmentationOptions& o, int radius) {
  cv::Mat part = cv::Mat::zeros(strong.size(), CV_8U);
  part(b.bounds).setTo(255, strong(b.bounds) & b.mask);
  cleanMask(part, radius);
  return SherdSegmenter().blobs(part, o);
}
}  // namespace

PhotoResult PhotoSegmenter::segment(const cv::Mat& rgb, const cv::Mat& background) const {
  PhotoResult r;
  if (rgb.empty() || rgb.type() != CV_8UC3) throw std::invalid_argument("PhotoSegmenter::segment: not an RGB image");
  ScaleBarOptions bar_options;
  bar_options.bar_length_cm = options_.bar_length_cm;
  r.bar = findScaleBar(rgb, bar_options);
  const double longer = std::max(rgb.cols, rgb.rows);
  const cv::Mat score = contrast(rgb, background, r);
  // hysteresis: weak pixels are kept where their connected region holds a strong one, so a
  // sherd keeps its dark paint and low-contrast rim but cloth texture does not grow blobs
  cv::Mat labels;
  const int n = cv::connectedComponents(score > options_.weak_contrast, labels, 8, CV_32S);
  std::vector<uint8_t> keep(n, 0);
  const cv::Mat strong = score > options_.strong_contrast;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const uint8_t* s = strong.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (s[x]) keep[l[x]] = 255;
    }
  }
  keep[0] = 0;
  cv::Mat fg(rgb.size(), CV_8U);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uint8_t* o = fg.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) o[x] = keep[l[x]];
  }
  // Sizes in mm from the bar; without it, from the typical sherd (the blob size a foreground
  // pixel belongs to, median over pixels so lint does not count), taken as kTypicalSherdMm.
  double px_per_mm = r.bar.found ? 0.1 * r.bar.px_per_cm : 0.0;
  if (!r.bar.found) {
    cv::Mat cc, stats, centroids;
    const int m = cv::connectedComponentsWithStats(fg, cc, stats, centroids, 8, CV_32S);
    std::vector<std::pair<int, int>> sizes;  // (area, area) weighted by area
    long total = 0;
    for (int i = 1; i < m; ++i) {
      sizes.emplace_back(stats.at<int>(i, cv::CC_STAT_AREA), 0);
      total += stats.at<int>(i, cv::CC_STAT_AREA);
    }
    std::sort(sizes.begin(), sizes.end());
    long seen = 0;
    double typical = 0.0;
    for (const auto& sz : sizes) {
      seen += sz.first;
      if (2 * seen >= total) {
        typical = sz.first;
        break;
      }
    }
    px_per_mm = std::clamp(std::sqrt(typical) / options_.typical_sherd_mm, longer / 1500.0, longer / 150.0);
  }
  const double min_side = options_.min_side_mm * px_per_mm;
  const int radius = std::max(1, cvRound(options_.clean_radius_mm * px_per_mm));
  cleanMask(fg, radius);
  removeFrame(fg, r);
  const double cell = longer / kCoarseCells;
  // on the floor, a chair, a bag beside the cloth, or a sliver along its edge (the outline is
  // known to about one coarse cell): left out before the costly splitting, and split parts below
  auto off_sheet = [&](const cv::Point2f& centre) {
    return !r.cloth_outline.empty() && cv::pointPolygonTest(r.cloth_outline, centre, true) < kOutlineCells * cell;
  };
  int off_cloth = 0;
  if (!r.cloth_outline.empty()) {
    cv::Mat cc, stats, centroids;
    const int m = cv::connectedComponentsWithStats(fg, cc, stats, centroids, 8, CV_32S);
    std::vector<uint8_t> on(m, 255);
    on[0] = 0;
    for (int i = 1; i < m; ++i) {
      if (!off_sheet(cv::Point2f(static_cast<float>(centroids.at<double>(i, 0)), static_cast<float>(centroids.at<double>(i, 1))))) continue;
      on[i] = 0;
      off_cloth += stats.at<int>(i, cv::CC_STAT_AREA) >= min_side * min_side;  // specks are not objects
    }
    for (int y = 0; y < fg.rows; ++y) {
      const int* l = cc.ptr<int>(y);
      uint8_t* o = fg.ptr<uint8_t>(y);
      for (int x = 0; x < fg.cols; ++x) o[x] = on[l[x]];
    }
  }
  std::vector<cv::Point2f> bar_corners;
  if (r.bar.found) {  // the bar and its card are not sherds
    cv::RotatedRect grown = r.bar.box;
    grown.size.width += static_cast<float>(2 * options_.bar_margin_cm * r.bar.px_per_cm);
    grown.size.height += static_cast<float>(2 * options_.bar_margin_cm * r.bar.px_per_cm);
    bar_corners.resize(4);
    grown.points(bar_corners.data());
    std::vector<cv::Point> poly(bar_corners.begin(), bar_corners.end());
    cv::fillConvexPoly(fg, poly, cv::Scalar(0));
  }
  r.foreground = fg;

  SegmentationOptions o;
  o.min_side_px = min_side;
  o.max_side_px = r.bar.found ? options_.max_side_mm * px_per_mm : options_.max_side_fraction * longer;
  o.border_margin = 0;  // sherds cut by the border count (flagged)
  o.split_min_neck = options_.split_min_neck;
  std::vector<Blob> blobs = SherdSegmenter().blobs(fg, o);
  splitAtSeams(blobs, rgb);

  std::vector<double> areas;
  for (const Blob& b : blobs) areas.push_back(b.pixels);
  double typical = 0.0;
  if (!areas.empty()) {
    std::nth_element(areas.begin(), areas.begin() + areas.size() / 2, areas.end());
    typical = areas[areas.size() / 2];
  }
  // a blob many sherds large and mostly below the strong contrast: cloth leaked in
  const auto clearOf = [&](const Blob& b) {
    return static_cast<double>(cv::countNonZero(strong(b.bounds) & b.mask)) / std::max(1, b.pixels);
  };
  std::vector<bool> cut_back(blobs.size(), false);
  int leaks = 0;
  for (size_t i = 0, n = blobs.size(); i < n; ++i) {
    if (n < kManyBlobs || blobs[i].pixels <= kSeveralTypical * typical || clearOf(blobs[i]) >= kLeakClear) continue;
    std::vector<Blob> parts = cutBackToStrong(blobs[i], strong, o, radius);
    // what stands out in it smaller than a sherd is a speck of the cloth or of what lies beside it
    parts.erase(std::remove_if(parts.begin(), parts.end(),
                               [&](const Blob& q) { return q.pixels < kLeakPartTypical * typical; }),
                parts.end());
    if (parts.empty()) continue;
    ++leaks;
    blobs[i] = std::move(parts[0]);
    cut_back[i] = true;
    for (size_t k = 1; k < parts.size(); ++k) {
      blobs.push_back(std::move(parts[k]));
      cut_back.push_back(true);
    }
  }
  if (leaks > 0) {
    r.warnings.emplace_back(std::to_string(leaks) + (leaks == 1 ? " region" : " regions") +
                            " of weak contrast many sherds large (cloth lit unevenly?) cut back to the sherds "
                            "standing out clearly in it: their outlines are flagged low_contrast");
  }
  const double mm_per_px = r.bar.found ? 10.0 / r.bar.px_per_cm : 0.0;
  bool strip_warned = false;
  for (size_t i = 0; i < blobs.size(); ++i) {
    Blob& b = blobs[i];
    if (!bar_corners.empty() && cv::pointPolygonTest(bar_corners, b.box.center, false) >= 0) continue;
    if (off_sheet(b.box.center)) {
      ++off_cloth;
      continue;
    }
    PhotoSherd s;
    const cv::Scalar c = cv::mean(rgb(b.bounds), b.mask);
    s.colour = cv::Vec3d(c[0], c[1], c[2]) / 255.0;
    s.length_mm = std::max(b.box.size.width, b.box.size.height) * mm_per_px;
    s.width_mm = std::min(b.box.size.width, b.box.size.height) * mm_per_px;
    s.area_mm2 = b.pixels * mm_per_px * mm_per_px;
    if (!r.bar.found) s.flags |= kNoScale;
    const bool left = b.bounds.x <= 1, top = b.bounds.y <= 1;
    const bool right = b.bounds.br().x >= rgb.cols - 1, bottom = b.bounds.br().y >= rgb.rows - 1;
    if (left || right || top || bottom) {
      // a thin strip along the border (frame, mount, the cloth's edge) is not a sherd cut by it
      const bool vertical = (left || right) && b.bounds.width <= 0.04 * rgb.cols && b.bounds.height >= 3 * b.bounds.width;
      const bool horizontal = (top || bottom) && b.bounds.height <= 0.04 * rgb.rows && b.bounds.width >= 3 * b.bounds.height;
      if (vertical || horizontal) {
        if (!strip_warned) r.warnings.emplace_back("a strip along the photo's border was left out (frame?)");
        strip_warned = true;
        continue;
      }
      s.flags |= kTouchesBorder;
    }
    // several sherds the split could not separate: far from convex, or far larger than the rest
    if (solidity(b.contour) < 0.8 || (blobs.size() >= kManyBlobs && b.pixels > kSeveralTypical * typical)) {
      s.flags |= kProbablySeveral;
    }
    // how much of it stands out clearly: a sherd mostly below the strong contrast (dark on a
    // dark cloth) has an outline that may be wrong
    const double clear = clearOf(b);
    if (clear < options_.min_clear) continue;  // cloth texture or a shadow edge, not a sherd
    if (clear < options_.low_contrast || cut_back[i]) s.flags |= kLowContrast;
    s.blob = std::move(b);
    r.sherds.push_back(std::move(s));
  }
  if (off_cloth > 0) {
    r.warnings.emplace_back(std::to_string(off_cloth) + (off_cloth == 1 ? " object" : " objects") +
                            " beside the cloth left out");
  }
  return r;
}

}  // namespace rascal_perception
