// segment_image: sherds and the scale bar in a photo (no ROS).
//   segment_image <photo> [--background auto|<empty.jpg>] [--json out.json] [--png out.png]
//                 [--mask foreground.png] [--bar-length 10] [--clusters 6]
// Prints the JSON to stdout when --json is not given.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "rascal_perception/PhotoSegmenter.hpp"

using namespace rascal_perception;

namespace {
int usage(FILE* to = stderr, int code = 2) {
  std::fprintf(to,
               "usage: segment_image <photo> [--background auto|<empty.jpg>] [--json out.json] [--png out.png]\n"
               "                     [--mask foreground.png] [--bar-length cm] [--clusters k]\n"
               "Finds the sherds and the black/white scale bar in a photo; prints JSON (sizes in mm when\n"
               "the bar is found). --background auto learns the background from the photo itself.\n");
  return code;
}

cv::Mat readRgb(const std::string& path) {
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) throw std::runtime_error("cannot read " + path);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

std::string json(const std::string& image, const cv::Mat& rgb, const PhotoResult& r) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(2);
  o << "{\n  \"image\": \"" << image << "\",\n  \"width\": " << rgb.cols << ",\n  \"height\": " << rgb.rows << ",\n";
  if (r.bar.found) {
    const cv::RotatedRect& b = r.bar.box;
    o << "  \"px_per_cm\": " << r.bar.px_per_cm << ",\n  \"scale_bar\": {\"centre\": [" << b.center.x << ", "
      << b.center.y << "], \"length_px\": " << std::max(b.size.width, b.size.height)
      << ", \"width_px\": " << std::min(b.size.width, b.size.height) << ", \"angle_deg\": " << b.angle << "},\n";
  } else {
    o << "  \"px_per_cm\": null,\n  \"scale_bar\": null,\n";
  }
  o << "  \"sherds\": [";
  for (size_t i = 0; i < r.sherds.size(); ++i) {
    const PhotoSherd& s = r.sherds[i];
    const cv::RotatedRect& b = s.blob.box;
    o << (i ? ",\n" : "\n") << "    {\"id\": " << i << ", \"centre_px\": [" << b.center.x << ", " << b.center.y
      << "], \"box_px\": [" << std::max(b.size.width, b.size.height) << ", " << std::min(b.size.width, b.size.height)
      << "], \"angle_deg\": " << b.angle << ", \"area_px\": " << s.blob.pixels;
    if (r.bar.found) {
      o << ", \"length_mm\": " << s.length_mm << ", \"width_mm\": " << s.width_mm << ", \"area_mm2\": " << s.area_mm2;
    }
    o << ", \"colour\": [" << s.colour[0] << ", " << s.colour[1] << ", " << s.colour[2] << "]}";
  }
  o << "\n  ]\n}\n";
  return o.str();
}

cv::Mat annotate(const cv::Mat& rgb, const PhotoResult& r) {
  cv::Mat out = rgb.clone();
  const int t = std::max(1, rgb.cols / 500);
  for (size_t i = 0; i < r.sherds.size(); ++i) {
    const PhotoSherd& s = r.sherds[i];
    cv::drawContours(out, std::vector<std::vector<cv::Point>>{s.blob.contour}, 0, cv::Scalar(255, 255, 0), t);
    cv::Point2f c[4];
    s.blob.box.points(c);
    for (int k = 0; k < 4; ++k) cv::line(out, c[k], c[(k + 1) % 4], cv::Scalar(0, 255, 0), t, cv::LINE_AA);
    char label[64];
    if (r.bar.found) {
      std::snprintf(label, sizeof(label), "%zu: %.0fx%.0f mm", i, s.length_mm, s.width_mm);
    } else {
      std::snprintf(label, sizeof(label), "%zu", i);
    }
    cv::putText(out, label, cv::Point(s.blob.bounds.x, s.blob.bounds.y - 4), cv::FONT_HERSHEY_SIMPLEX,
                0.4 * t, cv::Scalar(255, 255, 0), t, cv::LINE_AA);
  }
  if (r.bar.found) {
    cv::Point2f c[4];
    r.bar.box.points(c);
    for (int k = 0; k < 4; ++k) cv::line(out, c[k], c[(k + 1) % 4], cv::Scalar(255, 0, 255), t, cv::LINE_AA);
    char label[64];
    std::snprintf(label, sizeof(label), "scale bar: %.2f px/cm", r.bar.px_per_cm);
    cv::putText(out, label, cv::Point(static_cast<int>(r.bar.box.center.x) - 60, static_cast<int>(r.bar.box.center.y) - 30),
                cv::FONT_HERSHEY_SIMPLEX, 0.5 * t, cv::Scalar(255, 0, 255), t, cv::LINE_AA);
  }
  return out;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  if (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") return usage(stdout, 0);
  std::string image = argv[1], background = "auto", json_path, png_path, mask_path;
  PhotoSegmenter::Options options;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage();
    const std::string v = argv[++i];
    try {
      if (a == "--background") {
        background = v;
      } else if (a == "--json") {
        json_path = v;
      } else if (a == "--png") {
        png_path = v;
      } else if (a == "--mask") {
        mask_path = v;
      } else if (a == "--bar-length") {
        options.bar_length_cm = std::stod(v);
      } else if (a == "--clusters") {
        options.clusters = std::stoi(v);
      } else {
        return usage();
      }
    } catch (const std::exception&) {
      std::fprintf(stderr, "segment_image: bad value '%s' for %s\n", v.c_str(), a.c_str());
      return 2;
    }
  }
  try {
    const cv::Mat rgb = readRgb(image);
    const cv::Mat bg = background == "auto" ? cv::Mat() : readRgb(background);
    const PhotoResult r = PhotoSegmenter(options).segment(rgb, bg);
    const std::string text = json(image, rgb, r);
    if (json_path.empty()) {
      std::cout << text;
    } else {
      std::ofstream(json_path) << text;
    }
    if (!mask_path.empty() && !cv::imwrite(mask_path, r.foreground)) throw std::runtime_error("cannot write " + mask_path);
    if (!png_path.empty()) {
      cv::Mat bgr;
      cv::cvtColor(annotate(rgb, r), bgr, cv::COLOR_RGB2BGR);
      if (!cv::imwrite(png_path, bgr)) throw std::runtime_error("cannot write " + png_path);
    }
    std::fprintf(stderr, "segment_image: %zu sherds, scale bar %s\n", r.sherds.size(),
                 r.bar.found ? (std::to_string(r.bar.px_per_cm) + " px/cm").c_str() : "not found");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "segment_image: %s\n", e.what());
    return 1;
  }
  return 0;
}
