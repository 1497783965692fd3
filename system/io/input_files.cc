#include "system/io/input_files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "system/io/png_codec.h"

namespace cslam {

namespace fs = std::filesystem;

std::ifstream OpenTextFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  std::ifstream in;
  if (fs::is_regular_file(path, ec)) in.open(path);
  if (!in.is_open()) throw InputError(path, "cannot open the " + what + " (missing or unreadable)");
  return in;
}

std::vector<double> ParseNumbers(const std::string& text, const std::string& path, int line,
                                 const std::string& label) {
  std::istringstream s(text);
  std::vector<double> values;
  std::string token;
  while (s >> token) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !std::isfinite(v))
      throw InputError(path, line, (label.empty() ? "" : label + " ") + "field " +
                                       std::to_string(values.size() + 1) +
                                       ": expected a finite number, got '" + token + "'");
    values.push_back(v);
  }
  return values;
}

std::vector<std::string> ListPngFiles(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir, "expected an image folder; it is missing");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".png") files.push_back(entry.path().string());
  }
  if (ec) throw InputError(dir, "cannot list the folder: " + ec.message());
  if (files.empty()) throw InputError(dir, "expected *.png images; the folder has none");
  std::sort(files.begin(), files.end());
  return files;
}

cv::Mat LoadGreyImage(const std::string& path, int expected_width, int expected_height) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path, "expected an image file; it is missing");
  const cv::Mat image = ReadPng(path, PngPixels::kGrey8);
  if (expected_width > 0 && (image.cols != expected_width || image.rows != expected_height))
    throw InputError(path, "expected a " + std::to_string(expected_width) + "x" +
                               std::to_string(expected_height) + " image, got " +
                               std::to_string(image.cols) + "x" + std::to_string(image.rows));
  return image;
}

namespace {

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil), so
// drives across midnight or month ends keep increasing times.
long DaysFromCivil(int y, int m, int d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void CheckIncreasing(const std::vector<double>& t, const std::string& path, int line) {
  if (t.size() >= 2 && !(t.back() > t[t.size() - 2]))
    throw InputError(path, line, "expected increasing timestamps; this one is not after the previous");
}

}  // namespace

std::vector<double> ReadKittiRawTimestamps(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "timestamps file");
  std::vector<double> times;
  double first = 0;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    int y, mo, d, h, mi, consumed = 0;
    double seconds = 0;
    // Whole days/hours/minutes are differenced before adding the seconds so the 9-digit
    // fraction keeps its precision in a double.
    const int n = std::sscanf(line.c_str(), " %4d-%2d-%2d %2d:%2d:%lf%n", &y, &mo, &d, &h, &mi,
                              &seconds, &consumed);
    const bool rest_blank =
        n == 6 && line.find_first_not_of(" \t\r", static_cast<size_t>(consumed)) == std::string::npos;
    if (!rest_blank || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 || mi < 0 ||
        mi > 59 || !(seconds >= 0 && seconds < 61))
      throw InputError(path, line_no,
                       "expected a timestamp 'YYYY-MM-DD HH:MM:SS.nnnnnnnnn', got '" + line + "'");
    const double t = static_cast<double>(DaysFromCivil(y, mo, d)) * 86400.0 + h * 3600.0 +
                     mi * 60.0;
    if (times.empty()) first = t;
    times.push_back((t - first) + seconds);
    CheckIncreasing(times, path, line_no);
  }
  if (times.empty()) throw InputError(path, "expected one timestamp per frame; the file is empty");
  const double t0 = times.front();
  for (double& t : times) t -= t0;
  return times;
}

std::vector<double> ReadSecondsTimestamps(const std::string& path) {
  std::ifstream in = OpenTextFile(path, "timestamps file");
  std::vector<double> times;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto b = line.find_first_not_of(" \t\r");
    if (b == std::string::npos) continue;
    char* end = nullptr;
    const double v = std::strtod(line.c_str() + b, &end);
    const bool rest_blank = end != line.c_str() + b &&
                            std::string(end).find_first_not_of(" \t\r") == std::string::npos;
    if (!rest_blank || !std::isfinite(v))
      throw InputError(path, line_no, "expected one finite number of seconds, got '" + line + "'");
    times.push_back(v);
    CheckIncreasing(times, path, line_no);
  }
  if (times.empty()) throw InputError(path, "expected one timestamp per frame; the file is empty");
  const double t0 = times.front();
  for (double& t : times) t -= t0;
  return times;
}

}  // namespace cslam
