#include "rascal_perception/BackgroundStore.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <opencv2/core/persistence.hpp>
#include <stdexcept>

namespace rascal_perception {

namespace {
constexpr int kFormat = 1;  ///< bumped when what write() writes changes: older files are ignored

/// mkdir -p
void makeDirs(const std::string& dir) {
  for (size_t i = 1; i <= dir.size(); ++i) {
    if (i < dir.size() && dir[i] != '/') continue;
    const std::string part = dir.substr(0, i);
    if (::mkdir(part.c_str(), 0755) != 0 && errno != EEXIST) {
      throw std::runtime_error("cannot create " + part + ": " + std::strerror(errno));
    }
  }
}
}  // namespace

std::string BackgroundStore::path(const std::string& station) const {
  if (station.empty() || station.find('/') != std::string::npos || station[0] == '.') {
    throw std::invalid_argument("station name '" + station + "' cannot name a file");
  }
  return dir_ + "/" + station + ".yml.gz";
}

void BackgroundStore::save(const SherdDetector& detector, const std::string& station, const std::string& layout,
                           double learnt_at) const {
  const std::string file = path(station);
  const std::string partial = dir_ + "/." + station + ".partial.yml.gz";
  makeDirs(dir_);
  {
    cv::FileStorage fs(partial, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML | cv::FileStorage::BASE64);
    if (!fs.isOpened()) throw std::runtime_error("cannot write " + partial);
    fs << "format" << kFormat << "station" << station << "layout" << layout << "learnt_at" << learnt_at;
    if (!detector.write(station, fs)) {
      fs.release();
      std::remove(partial.c_str());
      throw std::invalid_argument("station " + station + " has no background model to save");
    }
  }
  if (std::rename(partial.c_str(), file.c_str()) != 0) {
    throw std::runtime_error("cannot replace " + file + ": " + std::strerror(errno));
  }
}

bool BackgroundStore::restore(SherdDetector& detector, const std::string& station, const std::string& layout,
                              double now, double max_age, std::string& message) const {
  const std::string file = path(station);
  message.clear();
  struct stat st;
  if (::stat(file.c_str(), &st) != 0) return false;
  char buf[256];
  try {
    cv::FileStorage fs(file, cv::FileStorage::READ);
    if (!fs.isOpened()) throw std::invalid_argument("cannot be read");
    if (static_cast<int>(fs["format"]) != kFormat || static_cast<std::string>(fs["station"]) != station) {
      message = file + " is of another format or station: not used";
      return false;
    }
    if (static_cast<std::string>(fs["layout"]) != layout) {  // moved (rascal calibrate) or re-measured
      message = file + " was learnt where the station stood before the layout changed: not used";
      return false;
    }
    const double age = now - static_cast<double>(fs["learnt_at"]);
    if (!(age >= 0.0 && age <= max_age)) {
      std::snprintf(buf, sizeof(buf), " was learnt %.0f s ago (more than %.0f s): not used", age, max_age);
      message = file + buf;
      return false;
    }
    detector.read(station, fs.root());
    std::snprintf(buf, sizeof(buf), " (learnt %.0f s ago)", age);
    message = "station " + station + ": background restored from " + file + buf;
    return true;
  } catch (const std::exception& e) {  // cv::Exception too: a truncated or foreign file
    message = file + ": " + e.what() + ": not used";
    return false;
  }
}

}  // namespace rascal_perception
