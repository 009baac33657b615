#include <gtest/gtest.h>

#include "detect.hpp"
#include "import_support.hpp"

namespace telltale::shore::import {
namespace {

using namespace test;

TEST(ImportDetect, EachFormatFromItsContent) {
  EXPECT_EQ(detect_format("timestamp,latitude,longitude,sog_kts,cog,hdg_true,heel,trim\r\n1,2,3"),
            Format::kVakarosCsv);
  EXPECT_EQ(detect_format("\n\nTimestamp,Latitude,Longitude,sog_kts,cog,hdg_true,roll,pitch\n"),
            Format::kVakarosCsv);
  EXPECT_EQ(detect_format("<?xml version=\"1.0\"?>\n<gpx version=\"1.0\">"), Format::kGpx);
  EXPECT_EQ(detect_format("$GPRMC,105640.00,A,3930.0000,N,00230.0000,E,10.0,045.0,080226,,,A\n"
                          "$HCHDT,047.5,T\n"),
            Format::kNmea);
  EXPECT_EQ(detect_format("1770548200000;A;$GPGGA,105640.00,3930.0000,N,00230.0000,E,1,08,0.9,5."
                          "0,M,50.0,M,,\n"),
            Format::kNmea);
  std::string vkx;
  put_u8(vkx, 0xFF);
  vkx.append(7, '\x01');
  put_u8(vkx, 0x02);
  vkx.append(44, '\0');
  EXPECT_EQ(detect_format(vkx), Format::kVkx);
  std::string tp, rec, vtk;
  pb_uint(tp, 1, 1770548200);
  pb_bytes(rec, 1, tp);
  put_u16(vtk, static_cast<unsigned>(rec.size()));
  vtk += rec;
  EXPECT_EQ(detect_format(vtk), Format::kVtk);
}

TEST(ImportDetect, UnknownContentIsNone) {
  EXPECT_FALSE(detect_format(""));
  EXPECT_FALSE(detect_format("hello, world\nthis is prose\n"));
  EXPECT_FALSE(detect_format("time,speed\n1,2\n"));
  EXPECT_FALSE(detect_format(std::string("\x00\x01\x02\x03", 4)));
  EXPECT_EQ(parse_format("vkx"), Format::kVkx);
  EXPECT_FALSE(parse_format("fit"));
}

}  // namespace
}  // namespace telltale::shore::import
