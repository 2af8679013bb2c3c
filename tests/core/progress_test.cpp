#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/progress.h"

namespace tender {
namespace {

std::string readAll(std::FILE* f) {
  std::rewind(f);
  std::string s;
  char buf[512];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) s.append(buf, n);
  return s;
}

TEST(Progress, Line) {
  EXPECT_EQ(Progress::line("tender sim", "tick", 60, 120, 2.0),
            "tender sim: [###############---------------]  50% tick 60 of 120, 0:02 left");
  EXPECT_EQ(Progress::line("x", "frame", 0, 10, 5.0),
            "x: [------------------------------]   0% frame 0 of 10, --:-- left");
  EXPECT_EQ(Progress::line("x", "tick", 10, 10, 5.0),
            "x: [##############################] 100% tick 10 of 10, 0:00 left");
}

TEST(Progress, Clock) {
  EXPECT_EQ(Progress::clock(0.4), "0:00");
  EXPECT_EQ(Progress::clock(7), "0:07");
  EXPECT_EQ(Progress::clock(754), "12:34");
  EXPECT_EQ(Progress::clock(3723), "1:02:03");
  EXPECT_EQ(Progress::clock(-1), "0:00");
}

TEST(Progress, DrawsInPlaceAndClears) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress p("t", "tick", 4, 0.0, f, true);
    p.update(1);
    p.update(2); // drawn only when 100 ms have passed since the first
    p.update(4); // the last step is always drawn
  }
  const std::string s = readAll(f);
  EXPECT_EQ(s.find('\n'), std::string::npos);
  EXPECT_NE(s.find("\rt: ["), std::string::npos);
  EXPECT_NE(s.find("tick 4 of 4"), std::string::npos);
  EXPECT_EQ(s.substr(s.size() - 4), "\r\033[K");
  std::fclose(f);
}

TEST(Progress, SilentWhenOffOrBeforeTheDelay) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress off("t", "tick", 4, 0.0, f, false);
    off.update(1);
    Progress late("t", "tick", 4, 3600.0, f, true);
    late.update(4);
  }
  EXPECT_EQ(readAll(f), "");
  std::fclose(f);
}

} // namespace
} // namespace tender
