// segment_image: sherds and the scale bar in a photo (no ROS). `segment_image --help` says it all.
#include <getopt.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rascal_perception/PhotoSegmenter.hpp"

using namespace rascal_perception;

namespace {
/// Whether two descriptors are one open file (`2>&1`): same device and inode.
bool sameFile(int a, int b) {
  struct stat sa {}, sb {};
  if (fstat(a, &sa) != 0 || fstat(b, &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

constexpr int kConfident = 0, kDoubtful = 1, kBadInput = 2;

const char* kHelp =
    "usage: segment_image PHOTO... [options]     (options may come before or after the photos)\n"
    "\n"
    "Finds every sherd and the 10 cm scale bar (half a chequer of 1 cm squares, half solid) in a\n"
    "photo of sherds on a cloth, and measures each sherd in mm once the bar is found.\n"
    "Several photos (segment_image tray/*.jpg) are segmented one after another in one run, which\n"
    "saves the start-up of one run per photo: stdout holds each photo's table under its name, or\n"
    "one JSON line per photo with \"photo\" last; the FILE options and --report are for one photo.\n"
    "\n"
    "options:\n"
    "  --json [FILE], -j    one JSON object on one line: \"sherds\", a list of one object per sherd\n"
    "                       (id, length_mm, width_mm, area_mm2, px_per_cm, scale (\"12.10 px/cm\"),\n"
    "                       flags, centre_px, box_px, length_px, width_px, angle_deg, area_px,\n"
    "                       colour), then sherd_count, px_per_cm (null without a bar), scale and\n"
    "                       summary: on stdout (no FILE, or '-'), else written to FILE as\n"
    "                       well as what stdout holds; a FILE not ending in .json needs --json=FILE\n"
    "  --report [FILE]      the whole result as one JSON object (summary, px/cm, the scale bar's\n"
    "                       box and doubt, the photo-wide doubts and the sherds): on stdout or FILE\n"
    "  --format table|json|report\n"
    "                       what stdout holds; without it, the table on a terminal and the JSON\n"
    "                       object when stdout is a pipe or a file. With JSON, stdout holds only\n"
    "                       the JSON; the one-line summary (count, px/cm, doubts) goes to stderr\n"
    "                       unless stderr is stdout (2>&1), so merged output still parses\n"
    "  --overlay FILE       write the overlay image there (default: PHOTO-STEM_segmented.jpg in the\n"
    "                       current folder): outlines and ids, flagged sherds in orange, the bar\n"
    "  --no-overlay         write no overlay image\n"
    "  --mask FILE          write the foreground mask (PNG)\n"
    "  --labels FILE        write each sherd's outline filled with its id (16-bit PNG, 0 = none)\n"
    "  --background FILE    a photo of the empty cloth from the same camera (default: learnt from\n"
    "                       the photo itself)\n"
    "  --bar-length CM      printed length of the scale bar (default 10)\n"
    "  --clusters K         colours of the first background guess, 2..12 (default 6)\n"
    "  -h, --help           this text\n"
    "\n"
    "table columns: id, length and width of the sherd's smallest enclosing rectangle [mm],\n"
    "area of its outline [mm2] (px and px2 without a scale bar), flags.\n"
    "flags: probably_several (shape or size says several touching sherds), touches_border (the\n"
    "sherd may be cut by the photo's edge), low_contrast (outline weak against the cloth),\n"
    "no_scale (no scale bar: sizes in px).\n"
    "exit codes: 0 a confident result; 1 doubtful (no scale bar, a doubtful bar, a sherd\n"
    "flagged, or the background model not trusted: the summary line says which); 2 bad usage or\n"
    "an unreadable photo (one line on stderr). With several photos, the worst of theirs; a photo\n"
    "that cannot be read is named and the others are still segmented.\n";

bool endsWith(std::string s, const std::string& tail) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// `--json` / `--report` take the next word as their FILE only when it is '-' or a .json name:
// last, before another option or before the photo they mean stdout (the common calls
// `segment_image PHOTO --json` and `segment_image --json PHOTO`). `-j` is `--json`.
std::vector<char*> withJsonFileResolved(int argc, char** argv) {
  static char kJson[] = "--json", kJsonStdout[] = "--json=-", kReportStdout[] = "--report=-";
  std::vector<char*> out(argv, argv + argc);
  for (size_t i = 1; i < out.size(); ++i) {
    if (std::string(out[i]) == "--") break;
    if (std::string(out[i]) == "-j") out[i] = kJson;
    const std::string word = out[i];
    if (word != "--json" && word != "--report") continue;
    const bool has_file = i + 1 < out.size() && (std::string(out[i + 1]) == "-" || endsWith(out[i + 1], ".json"));
    if (!has_file) out[i] = word == "--json" ? kJsonStdout : kReportStdout;
  }
  return out;
}

int badUsage(const std::string& line) {
  std::fprintf(stderr, "segment_image: %s (segment_image --help lists the options)\n", line.c_str());
  return kBadInput;
}

cv::Mat readRgb(const std::string& path, const char* what) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error(std::string(what) + " '" + path + "' does not exist; check the path");
  }
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) {
    throw std::runtime_error(std::string(what) + " '" + path + "' cannot be read as an image; check the path");
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

/// Photo-wide doubts, one phrase each (empty: a confident result).
std::vector<std::string> doubts(const PhotoResult& r) {
  std::vector<std::string> d;
  if (!r.bar.found) d.push_back("no scale bar: sizes in px");
  if (r.bar.found && !r.bar.doubt.empty()) d.push_back("scale bar doubtful: " + r.bar.doubt);
  for (const std::string& w : r.warnings) d.push_back(w);
  if (!r.background_trusted && r.warnings.empty()) d.push_back("background model not trusted");
  int flagged = 0;
  for (const PhotoSherd& s : r.sherds) flagged += (s.flags & ~static_cast<unsigned>(kNoScale)) != 0;
  if (flagged) d.push_back(std::to_string(flagged) + " sherd" + (flagged == 1 ? "" : "s") + " flagged");
  return d;
}

std::string summaryOf(const PhotoResult& r) {
  std::string summary = std::to_string(r.sherds.size()) + " sherds, ";
  summary += r.bar.found ? cv::format("scale bar %.2f px/cm", r.bar.px_per_cm) : std::string("no scale bar");
  const std::vector<std::string> d = doubts(r);
  for (const std::string& x : d) summary += "; " + x;
  return summary + (d.empty() ? "" : " (doubtful: exit 1)");
}

void twoDecimals(std::ostream& o) {
  o.setf(std::ios::fixed);
  o.precision(2);
}

/// One sherd as a JSON object: what a catalogue wants first (sizes, scale, flags), then pixels.
void sherdJson(const PhotoResult& r, size_t i, std::ostream& o) {
  const PhotoSherd& s = r.sherds[i];
  const cv::RotatedRect& b = s.blob.box;
  o << "{\"id\": " << i + 1;
  if (r.bar.found) {
    o << ", \"length_mm\": " << s.length_mm << ", \"width_mm\": " << s.width_mm << ", \"area_mm2\": " << s.area_mm2
      << ", \"px_per_cm\": " << r.bar.px_per_cm << ", \"scale\": \"" << r.bar.px_per_cm << " px/cm\"";
  } else {
    o << ", \"length_mm\": null, \"width_mm\": null, \"area_mm2\": null, \"px_per_cm\": null, "
         "\"scale\": \"no scale bar\"";
  }
  o << ", \"flags\": [";
  const std::vector<std::string> f = flagNames(s.flags);
  for (size_t k = 0; k < f.size(); ++k) o << (k ? ", " : "") << "\"" << f[k] << "\"";
  o << "], \"centre_px\": [" << b.center.x << ", " << b.center.y << "], \"box_px\": ["
    << std::max(b.size.width, b.size.height) << ", " << std::min(b.size.width, b.size.height)
    << "], \"length_px\": " << std::max(b.size.width, b.size.height)
    << ", \"width_px\": " << std::min(b.size.width, b.size.height) << ", \"angle_deg\": " << b.angle
    << ", \"area_px\": " << s.blob.pixels << ", \"colour\": [" << s.colour[0] << ", " << s.colour[1] << ", " << s.colour[2] << "]}";
}

/// `--json`: one line, {"sherds": [...], "sherd_count", "px_per_cm", "scale", "summary"}, and
/// "photo" last where several photos are segmented at once (a line each).
std::string sherdList(const PhotoResult& r, const std::string* photo = nullptr) {
  std::ostringstream o;
  twoDecimals(o);
  o << "{\"sherds\": [";
  for (size_t i = 0; i < r.sherds.size(); ++i) {
    o << (i ? ", " : "");
    sherdJson(r, i, o);
  }
  // the sherd list first, then only scalars: a reader cutting from the first '[' to the last ']'
  // gets the list, one parsing the whole line gets px/cm too
  o << "], \"sherd_count\": " << r.sherds.size() << ", \"px_per_cm\": ";
  if (r.bar.found) {
    o << r.bar.px_per_cm << ", \"scale\": \"" << r.bar.px_per_cm << " px/cm\"";
  } else {
    o << "null, \"scale\": \"no scale bar\"";
  }
  o << ", \"summary\": \"" << escape(summaryOf(r)) << "\"";
  if (photo) o << ", \"photo\": \"" << escape(*photo) << "\"";
  o << "}\n";
  return o.str();
}

/// `--report`: the whole result, the photo-wide findings beside the sherds.
std::string report(const std::string& image, const cv::Mat& rgb, const PhotoResult& r) {
  std::ostringstream o;
  twoDecimals(o);
  o << "{\n  \"image\": \"" << escape(image) << "\",\n  \"summary\": \"" << escape(summaryOf(r))
    << "\",\n  \"sherd_count\": " << r.sherds.size() << ",\n  \"width\": " << rgb.cols << ",\n  \"height\": " << rgb.rows
    << ",\n";
  if (r.bar.found) {
    const cv::RotatedRect& b = r.bar.box;
    o << "  \"px_per_cm\": " << r.bar.px_per_cm << ",\n  \"scale_bar\": {\"centre\": [" << b.center.x << ", "
      << b.center.y << "], \"length_px\": " << std::max(b.size.width, b.size.height)
      << ", \"width_px\": " << std::min(b.size.width, b.size.height) << ", \"angle_deg\": " << b.angle
      << ", \"squares\": " << r.bar.squares << ", \"doubt\": "
      << (r.bar.doubt.empty() ? "null" : "\"" + escape(r.bar.doubt) + "\"") << "},\n";
  } else {
    o << "  \"px_per_cm\": null,\n  \"scale_bar\": null,\n";
  }
  o << "  \"background_trusted\": " << (r.background_trusted ? "true" : "false") << ",\n  \"doubts\": [";
  const std::vector<std::string> d = doubts(r);
  for (size_t i = 0; i < d.size(); ++i) o << (i ? ", " : "") << "\"" << escape(d[i]) << "\"";
  o << "],\n  \"sherds\": [";
  for (size_t i = 0; i < r.sherds.size(); ++i) {
    o << (i ? ",\n    " : "\n    ");
    sherdJson(r, i, o);
  }
  o << "\n  ]\n}\n";
  return o.str();
}

void table(const PhotoResult& r, std::ostream& o) {
  const bool mm = r.bar.found;
  char line[256];
  std::snprintf(line, sizeof(line), "%4s %10s %10s %11s  %s\n", "id", mm ? "length mm" : "length px",
                mm ? "width mm" : "width px", mm ? "area mm2" : "area px2", "flags");
  o << line;
  for (size_t i = 0; i < r.sherds.size(); ++i) {
    const PhotoSherd& s = r.sherds[i];
    const double l = mm ? s.length_mm : std::max(s.blob.box.size.width, s.blob.box.size.height);
    const double w = mm ? s.width_mm : std::min(s.blob.box.size.width, s.blob.box.size.height);
    const double a = mm ? s.area_mm2 : s.blob.pixels;
    std::string flags;
    for (const std::string& f : flagNames(s.flags & ~static_cast<unsigned>(kNoScale))) flags += (flags.empty() ? "" : ",") + f;
    std::snprintf(line, sizeof(line), "%4zu %10.1f %10.1f %11.0f  %s\n", i + 1, l, w, a, flags.c_str());
    o << line;
  }
}

cv::Mat annotate(const cv::Mat& rgb, const PhotoResult& r) {
  cv::Mat out = rgb.clone();
  const int t = std::max(1, rgb.cols / 500);
  if (!r.cloth_outline.empty()) {  // where the cloth was taken to be: nothing outside is counted
    cv::polylines(out, std::vector<std::vector<cv::Point>>{r.cloth_outline}, true, cv::Scalar(120, 255, 120), t,
                  cv::LINE_AA);
  }
  for (size_t i = 0; i < r.sherds.size(); ++i) {
    const PhotoSherd& s = r.sherds[i];
    const bool flagged = (s.flags & ~static_cast<unsigned>(kNoScale)) != 0;
    const cv::Scalar colour = flagged ? cv::Scalar(255, 140, 0) : cv::Scalar(0, 255, 255);
    cv::drawContours(out, std::vector<std::vector<cv::Point>>{s.blob.contour}, 0, colour, t, cv::LINE_AA);
    char label[64];
    std::snprintf(label, sizeof(label), "%zu%s", i + 1, flagged ? "?" : "");
    cv::putText(out, label, cv::Point(s.blob.bounds.x, std::max(10, s.blob.bounds.y - 4)), cv::FONT_HERSHEY_SIMPLEX,
                0.45 * t, colour, t, cv::LINE_AA);
  }
  if (r.bar.found) {
    cv::Point2f c[4];
    r.bar.box.points(c);
    for (int k = 0; k < 4; ++k) cv::line(out, c[k], c[(k + 1) % 4], cv::Scalar(255, 0, 255), t, cv::LINE_AA);
    char label[64];
    std::snprintf(label, sizeof(label), "scale bar %.2f px/cm%s", r.bar.px_per_cm, r.bar.doubt.empty() ? "" : " ?");
    cv::putText(out, label, cv::Point(static_cast<int>(r.bar.box.center.x) - 70, static_cast<int>(r.bar.box.center.y) - 25),
                cv::FONT_HERSHEY_SIMPLEX, 0.5 * t, cv::Scalar(255, 0, 255), t, cv::LINE_AA);
  }
  return out;
}
/// What to write for each photo, from the options.
struct Output {
  std::string format;  // what stdout holds: table, json or report
  std::string json_path, report_path, overlay_path, mask_path, labels_path;
  bool overlay = true;
  bool several = false;  // several photos: each one's table is titled, its JSON line names it
};

/// One photo through the segmentation and out as `out` says: its exit code.
int segmentPhoto(const std::string& image, const cv::Mat& bg, const PhotoSegmenter& segmenter, const Output& out) {
  const bool default_overlay = out.overlay && out.overlay_path.empty();
  const std::string overlay_path =
      default_overlay ? std::filesystem::path(image).stem().string() + "_segmented.jpg" : out.overlay_path;
  PhotoResult r;
  cv::Mat rgb;
  try {
    rgb = readRgb(image, "photo");
    r = segmenter.segment(rgb, bg);
  } catch (const std::exception& e) {
    return badUsage(e.what());
  }
  try {
    const std::pair<const std::string*, std::string> files[] = {{&out.json_path, "--json"},
                                                                {&out.report_path, "--report"}};
    for (const auto& [path, option] : files) {
      if (path->empty()) continue;
      std::ofstream f(*path);
      if (!(f << (option == "--json" ? sherdList(r) : report(image, rgb, r)))) {
        throw std::runtime_error("cannot write " + option + " " + *path);
      }
    }
    if (out.format == "json") std::cout << sherdList(r, out.several ? &image : nullptr) << std::flush;
    if (out.format == "report") std::cout << report(image, rgb, r);
    if (out.format == "table") {
      if (out.several) std::cout << image << "\n";
      table(r, std::cout);
      if (out.several) std::cout << "\n";
      std::cout << std::flush;
    }
    if (!out.mask_path.empty() && !cv::imwrite(out.mask_path, r.foreground)) {
      throw std::runtime_error("cannot write --mask " + out.mask_path);
    }
    if (!out.labels_path.empty()) {  // the ids of the table and the JSON, for tools that measure each sherd
      cv::Mat labels = cv::Mat::zeros(rgb.size(), CV_16U);
      for (size_t i = 0; i < r.sherds.size(); ++i) {
        cv::drawContours(labels, std::vector<std::vector<cv::Point>>{r.sherds[i].blob.contour}, 0,
                         cv::Scalar(static_cast<double>(i + 1)), cv::FILLED);
      }
      if (!cv::imwrite(out.labels_path, labels)) throw std::runtime_error("cannot write --labels " + out.labels_path);
    }
    if (out.overlay) {
      cv::Mat bgr;
      cv::cvtColor(annotate(rgb, r), bgr, cv::COLOR_RGB2BGR);
      bool written = false;
      try {
        written = cv::imwrite(overlay_path, bgr);
      } catch (const cv::Exception&) {
      }
      // The default overlay lands in the current folder, which may be read-only: the result is
      // still good, so that is a warning; an --overlay asked for is an error.
      if (!written && default_overlay && out.format != "table") {
        // stdout is JSON for a program: stderr stays empty so merged output still parses
      } else if (!written && default_overlay) {
        std::fprintf(stderr, "segment_image: warning: cannot write the overlay %s here; use --overlay FILE or --no-overlay\n",
                     overlay_path.c_str());
      } else if (!written) {
        throw std::runtime_error("cannot write --overlay " + overlay_path);
      }
    }
  } catch (const std::exception& e) {
    return badUsage(e.what());
  }
  // The summary (count, px/cm, doubts) goes to stderr for a person or a log, except when stderr
  // is the very pipe or file stdout is: there it would spoil the JSON a program parses.
  if (out.format == "table" || (out.format == "json" && !sameFile(STDOUT_FILENO, STDERR_FILENO))) {
    std::fprintf(stderr, "segment_image: %s%s\n", out.several ? (image + ": ").c_str() : "", summaryOf(r).c_str());
  }
  return doubts(r).empty() ? kConfident : kDoubtful;
}
}  // namespace

int main(int argc, char** argv) {
  static const option kLong[] = {{"json", required_argument, nullptr, 'j'},
                                 {"report", required_argument, nullptr, 'r'},
                                 {"format", required_argument, nullptr, 'f'},
                                 {"overlay", required_argument, nullptr, 'o'},
                                 {"no-overlay", no_argument, nullptr, 'n'},
                                 {"mask", required_argument, nullptr, 'm'},
                                 {"labels", required_argument, nullptr, 'L'},
                                 {"background", required_argument, nullptr, 'b'},
                                 {"bar-length", required_argument, nullptr, 'l'},
                                 {"clusters", required_argument, nullptr, 'k'},
                                 {"help", no_argument, nullptr, 'h'},
                                 {nullptr, 0, nullptr, 0}};
  Output out;  // the options say what to write for each photo
  std::string background;
  PhotoSegmenter::Options options;
  opterr = 0;  // our own one-line messages
  std::vector<char*> args = withJsonFileResolved(argc, argv);
  argv = args.data();
  int c;
  while ((c = getopt_long(argc, argv, ":h", kLong, nullptr)) != -1) {
    const std::string arg = optarg ? optarg : "";
    try {
      switch (c) {
        case 'j': out.json_path = arg; break;
        case 'r': out.report_path = arg; break;
        case 'f':
          if (arg != "table" && arg != "json" && arg != "report") {
            return badUsage("bad value '" + arg + "' for --format (table, json or report)");
          }
          out.format = arg;
          break;
        case 'o': out.overlay_path = arg; break;
        case 'n': out.overlay = false; break;
        case 'm': out.mask_path = arg; break;
        case 'L': out.labels_path = arg; break;
        case 'b': background = arg; break;
        case 'l': {
          size_t used = 0;
          options.bar_length_cm = std::stod(arg, &used);
          if (used != arg.size() || !(options.bar_length_cm > 0.5 && options.bar_length_cm < 100)) throw std::invalid_argument(arg);
          break;
        }
        case 'k': {
          size_t used = 0;
          options.clusters = std::stoi(arg, &used);
          if (used != arg.size() || options.clusters < 2 || options.clusters > 12) throw std::invalid_argument(arg);
          break;
        }
        case 'h': std::fputs(kHelp, stdout); return 0;
        case ':': return badUsage(std::string(argv[optind - 1]) + " needs a value");
        default: return badUsage("unknown option " + std::string(argv[optind - 1]));
      }
    } catch (const std::exception&) {
      return badUsage("bad value '" + arg + "' for --" +
                      (c == 'l' ? std::string("bar-length (a length in cm, e.g. 10)") : std::string("clusters (2..12)")));
    }
  }
  if (out.json_path == "-" && out.report_path == "-") return badUsage("--json and --report cannot both go to stdout");
  const std::string asked = out.json_path == "-" ? "json" : out.report_path == "-" ? "report" : "";
  if (!out.format.empty() && !asked.empty() && out.format != asked) {
    return badUsage("--format " + out.format + " and --" + asked + " - ask for different things on stdout");
  }
  // A person at a terminal reads the table; a pipe or a file gets what a program reads.
  if (out.format.empty()) out.format = !asked.empty() ? asked : isatty(STDOUT_FILENO) ? "table" : "json";
  if (out.json_path == "-") out.json_path.clear();
  if (out.report_path == "-") out.report_path.clear();
  if (optind >= argc) return badUsage("no photo given");
  out.several = argc - optind > 1;
  if (out.several) {
    // a FILE names one photo's output; several photos write only to stdout and their overlays
    const std::pair<const std::string*, std::string> one_file[] = {{&out.json_path, "--json FILE"},
                                                                   {&out.report_path, "--report FILE"},
                                                                   {&out.overlay_path, "--overlay FILE"},
                                                                   {&out.mask_path, "--mask FILE"},
                                                                   {&out.labels_path, "--labels FILE"}};
    for (const auto& [path, option] : one_file) {
      if (!path->empty()) {
        return badUsage(option + " is one photo's; with " + std::to_string(argc - optind) +
                        " photos leave it out (stdout has every photo; overlays go to PHOTO-STEM_segmented.jpg)");
      }
    }
    if (out.format == "report") {
      return badUsage("--report is one photo's; with several photos use --json (one line per photo)");
    }
  }
  cv::setNumThreads(1);
  cv::Mat bg;
  try {
    if (!background.empty()) bg = readRgb(background, "--background");
  } catch (const std::exception& e) {
    return badUsage(e.what());
  }
  // the worst of the photos' codes; a photo that cannot be read does not stop the others
  int code = kConfident;
  const PhotoSegmenter segmenter(options);
  for (int i = optind; i < argc; ++i) code = std::max(code, segmentPhoto(argv[i], bg, segmenter, out));
  return code;
}
