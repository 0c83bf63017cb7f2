// BackgroundStore: a station's background written by one detector and restored by another (a
// restarted node) finds the same sherd in the same place; a stale, foreign or broken file is not
// used and says why.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>

#include "SimScenes.hpp"
#include "rascal_perception/BackgroundStore.hpp"
#include "rascal_perception/SherdDetector.hpp"

using namespace rascal_perception;
using namespace rascal_perception_test;
using rascal_workcell::StationType;

namespace {

const PerceptionConfig& config() { return shippedDetector().config; }

/// A scratch folder, removed with what is in it.
struct TempDir {
  std::string root;
  TempDir() {
    char tmpl[] = "/tmp/rascal_backgrounds_XXXXXX";
    const char* dir = ::mkdtemp(tmpl);
    if (!dir) throw std::runtime_error("mkdtemp failed");
    root = dir;
  }
  ~TempDir() { (void)std::system(("rm -rf '" + root + "'").c_str()); }
  std::string kept() const { return root + "/kept"; }  // not there yet: save creates it
};

struct ScaleScene {
  Frame empty, loaded;
  std::string name;
  double surface = 0.0;
};

/// The scale empty (for calibration) and with one sherd on it, from the same wrist pose.
const ScaleScene& scaleScene() {
  static const ScaleScene s = [] {
    ScaleScene out;
    const rascal_workcell::Station& scale = station(StationType::Scale);
    rascal_sim::Scenario sc = generated(301, 1, 0.8, 5000, 0.0);
    sc.sherds[0].pose = Eigen::Vector3d(scale.area.centre.x(), scale.area.centre.y(), 0.4);
    rascal_sim::Scenario empty = sc;
    empty.sherds.clear();
    const rascal_sim::JointVector q = cameraOver(scale.area.centre);
    out.empty = render(empty, q);
    out.loaded = render(sc, q);
    out.name = scale.name;
    out.surface = scale.surface_z;
    return out;
  }();
  return s;
}

/// A detector that has learnt the empty scale of scaleScene().
SherdDetector learntOnEmptyScale() {
  const ScaleScene& s = scaleScene();
  SherdDetector d(config());
  const CalibrationResult c = d.calibrate(s.name, s.empty.rgb, s.empty.depth, s.empty.view, s.surface);
  if (!c.success) throw std::runtime_error("calibration of the empty scale failed: " + c.message);
  return d;
}

}  // namespace

TEST(BackgroundStore, ARestoredBackgroundFindsWhatTheLearntOneFinds) {
  const ScaleScene& s = scaleScene();
  const TempDir tmp;
  const BackgroundStore store(tmp.kept());
  SherdDetector learnt = learntOnEmptyScale();
  store.save(learnt, s.name, "here", 1000.0);

  SherdDetector restarted(config());
  ASSERT_FALSE(restarted.calibrated(s.name));
  std::string message;
  ASSERT_TRUE(store.restore(restarted, s.name, "here", 1000.0 + 60.0, 3600.0, message)) << message;
  EXPECT_NE(message.find("restored"), std::string::npos) << message;
  EXPECT_NE(message.find("60 s ago"), std::string::npos) << message;
  ASSERT_TRUE(restarted.calibrated(s.name));

  const DetectionResult a = learnt.detect(s.name, s.loaded.rgb, s.loaded.depth, s.loaded.view, s.surface);
  const DetectionResult b = restarted.detect(s.name, s.loaded.rgb, s.loaded.depth, s.loaded.view, s.surface);
  ASSERT_EQ(a.sherds.size(), 1u);
  ASSERT_EQ(b.sherds.size(), 1u);
  EXPECT_LT((a.sherds[0].centre - b.sherds[0].centre).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(a.sherds[0].length, b.sherds[0].length);
  EXPECT_DOUBLE_EQ(a.sherds[0].width, b.sherds[0].width);
  // and the empty station is still empty to it
  EXPECT_TRUE(restarted.detect(s.name, s.empty.rgb, s.empty.depth, s.empty.view, s.surface).sherds.empty());
}

TEST(BackgroundStore, AStaleForeignOrBrokenFileIsNotUsed) {
  const ScaleScene& s = scaleScene();
  const TempDir tmp;
  const BackgroundStore store(tmp.kept());
  const SherdDetector learnt = learntOnEmptyScale();
  SherdDetector d(config());
  std::string message;

  // none kept yet: nothing to say
  EXPECT_FALSE(store.restore(d, s.name, "here", 0.0, 3600.0, message));
  EXPECT_EQ(message, "");
  // no model: nothing written
  EXPECT_THROW(store.save(d, s.name, "here", 0.0), std::invalid_argument);

  store.save(learnt, s.name, "here", 1000.0);
  EXPECT_FALSE(store.restore(d, s.name, "here", 1000.0 + 7200.0, 3600.0, message));
  EXPECT_NE(message.find("7200 s ago (more than 3600 s): not used"), std::string::npos) << message;
  EXPECT_FALSE(store.restore(d, s.name, "here", 900.0, 3600.0, message));  // learnt "in the future": a clock set back
  // the station moved since (rascal calibrate wrote a corrected layout)
  EXPECT_FALSE(store.restore(d, s.name, "moved", 1000.0, 3600.0, message));
  EXPECT_NE(message.find("before the layout changed: not used"), std::string::npos) << message;
  EXPECT_FALSE(d.calibrated(s.name));

  // another station's file under this name
  std::rename(store.path(s.name).c_str(), store.path("camera").c_str());
  EXPECT_FALSE(store.restore(d, "camera", "here", 1000.0, 3600.0, message));
  EXPECT_NE(message.find("another format or station"), std::string::npos) << message;

  // cut short (a full disk)
  store.save(learnt, s.name, "here", 1000.0);
  {
    std::ifstream in(store.path(s.name), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream out(store.path(s.name), std::ios::binary | std::ios::trunc);
    out << bytes.substr(0, bytes.size() / 2);
  }
  EXPECT_FALSE(store.restore(d, s.name, "here", 1000.0, 3600.0, message));
  EXPECT_NE(message.find("not used"), std::string::npos) << message;
  EXPECT_FALSE(d.calibrated(s.name));

  EXPECT_THROW(store.path("../scale"), std::invalid_argument);
}

TEST(BackgroundStore, AFieldMissingFromAKeptBackgroundIsRefusedNotReadAsZero) {
  // FileNode reads a missing number as 0: a focal length of 0 or a cluster's hue of 0 would
  // make a wrong model without a word
  const ScaleScene& s = scaleScene();
  const SherdDetector learnt = learntOnEmptyScale();
  cv::FileStorage out(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  ASSERT_TRUE(learnt.write(s.name, out));
  const std::string whole = out.releaseAndGetString();
  for (const std::string key : {"fx", "surface_z", "hue_tolerance", "saturation"}) {
    std::string cut;
    std::istringstream lines(whole);
    bool dropped = false;
    for (std::string line; std::getline(lines, line);) {
      const size_t k = line.find_first_not_of(' ');
      if (!dropped && k != std::string::npos && line.compare(k, key.size() + 1, key + ":") == 0) {
        dropped = true;  // the first such field only
        continue;
      }
      cut += line + "\n";
    }
    ASSERT_TRUE(dropped) << key;
    cv::FileStorage in(cut, cv::FileStorage::READ | cv::FileStorage::MEMORY);
    SherdDetector d(config());
    try {
      d.read(s.name, in.root());
      ADD_FAILURE() << "read without " << key;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key + " missing"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(d.calibrated(s.name)) << key;
  }
  // and the whole file reads
  cv::FileStorage in(whole, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  SherdDetector d(config());
  d.read(s.name, in.root());
  EXPECT_TRUE(d.calibrated(s.name));
}
