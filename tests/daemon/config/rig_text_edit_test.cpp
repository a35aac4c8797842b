// editRigText (daemon/config/rig_text_edit.hpp) on a rig file as people keep them: comments
// everywhere, block and flow styles, keys of their own. Only the edited values change; every
// other byte is as it was, and the result reads as the edit says.

#include "daemon/config/rig_text_edit.hpp"

#include <array>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace surroundd::daemon {
namespace {

using ::testing::HasSubstr;

constexpr std::string_view kRig =
    "# Our test car, measured 2024-05-02.\n"
    "cameras:\n"
    "  # the grille camera\n"
    "  - name: front\n"
    "    lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 300, fy_px: 300,\n"
    "           cx_px: 320, cy_px: 180}  # from the supplier's sheet\n"
    "    mount: {x_m: 2.1, y_m: 0, z_m: 0.6, yaw_deg: 0, pitch_deg: -20, roll_deg: 0}\n"
    "    our_part_number: FC-12   # a key of our own\n"
    "\n"
    "  # over the number plate\n"
    "  - name: back\n"
    "    mount:\n"
    "      x_m: -2.2      # measured with a tape\n"
    "      y_m: 0\n"
    "      z_m: 0.9\n"
    "      yaw_deg: 180\n"
    "    # the lens follows\n"
    "    lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 300, fy_px: 300, cx_px: "
    "320, cy_px: 180}\n"
    "  - {name: left, lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 300, "
    "fy_px: 300, cx_px: 320, cy_px: 180}}\n"
    "  - name: right\n"
    "    lens: {model: pinhole, width_px: 640, height_px: 360, fx_px: 300, fy_px: 300, cx_px: "
    "320, cy_px: 180}\n"
    "vehicle: {length_m: 4.65}  # the brochure's\n";

const std::string kMount = "{x_m: 1, y_m: 2, z_m: 3}";

// `text` less every occurrence of the pieces (each expected exactly once).
std::string without(std::string text, std::initializer_list<std::string_view> pieces) {
  for (const auto piece : pieces) {
    const auto at = text.find(piece);
    EXPECT_NE(at, std::string::npos) << piece;
    if (at != std::string::npos) text.erase(at, piece.size());
  }
  return text;
}

TEST(RigTextEdit, AFlowValueIsReplacedOnItsLineWithItsComment) {
  const std::array<RigTextEdit, 1> edit{{{"front", kMount}}};
  const std::string edited = editRigText(std::string(kRig), "mount", edit, "calibrated");
  EXPECT_EQ(without(edited, {kMount + "  # calibrated"}),
            without(std::string(kRig),
                    {"{x_m: 2.1, y_m: 0, z_m: 0.6, yaw_deg: 0, pitch_deg: -20, roll_deg: 0}"}));
  EXPECT_EQ(YAML::Load(edited)["cameras"][0]["mount"]["z_m"].as<double>(), 3);
  // A value over two lines, its old comment going with it.
  const std::array<RigTextEdit, 1> lens{{{"front", "{model: fisheye}"}}};
  const std::string relensed = editRigText(std::string(kRig), "lens", lens, "new");
  EXPECT_THAT(relensed, HasSubstr("    lens: {model: fisheye}  # new\n    mount: {x_m: 2.1"));
  EXPECT_EQ(relensed.find("supplier"), std::string::npos);
}

TEST(RigTextEdit, ABlockValueIsReplacedUpToItsLastLineLeavingTheNextKeysComment) {
  const std::array<RigTextEdit, 1> edit{{{"back", kMount}}};
  const std::string edited = editRigText(std::string(kRig), "mount", edit, "calibrated");
  EXPECT_EQ(without(edited, {kMount + "  # calibrated"}),
            without(std::string(kRig), {"x_m: -2.2      # measured with a tape\n      y_m: 0\n"
                                        "      z_m: 0.9\n      yaw_deg: 180"}));
  EXPECT_THAT(edited, HasSubstr("  # calibrated\n    # the lens follows\n    lens:"));
  EXPECT_EQ(YAML::Load(edited)["cameras"][1]["mount"]["y_m"].as<double>(), 2);
}

TEST(RigTextEdit, AMissingKeyIsAddedInTheEntrysStyle) {
  const std::array<RigTextEdit, 2> edits{{{"right", kMount}, {"left", "{x_m: 9}"}}};
  const std::string edited = editRigText(std::string(kRig), "mount", edits, "measured");
  // A block entry: a line of its own at the column of its keys; a flow entry: its last pair.
  EXPECT_THAT(edited, HasSubstr("cx_px: 320, cy_px: 180}\n    mount: " + kMount +
                                "  # measured\nvehicle:"));
  EXPECT_THAT(edited, HasSubstr("cy_px: 180}, mount: {x_m: 9}}\n"));
  const YAML::Node rig = YAML::Load(edited);
  EXPECT_EQ(rig["cameras"][3]["mount"]["y_m"].as<double>(), 2);
  EXPECT_EQ(rig["cameras"][2]["mount"]["x_m"].as<double>(), 9);
  EXPECT_EQ(rig["vehicle"]["length_m"].as<double>(), 4.65);
  EXPECT_EQ(without(edited, {"\n    mount: " + kMount + "  # measured", ", mount: {x_m: 9}"}),
            std::string(kRig));
}

TEST(RigTextEdit, AValueInsideAFlowEntryIsReplacedThere) {
  const std::array<RigTextEdit, 1> edit{{{"left", "{model: fisheye}"}}};
  const std::string edited = editRigText(std::string(kRig), "lens", edit, "new");
  EXPECT_THAT(edited, HasSubstr("  - {name: left, lens: {model: fisheye}}\n"));
  EXPECT_EQ(YAML::Load(edited)["cameras"][2]["lens"]["model"].as<std::string>(), "fisheye");
}

// From a review: the last camera's block value in a file with no newline at its end; a plain
// scalar with an apostrophe and a comment inside a flow value.
TEST(RigTextEdit, TheFilesEndAndApostrophesAreReadAsYamlReadsThem) {
  const std::string lastBlock = "cameras:\n  - name: back\n    mount:\n      x_m: 1\n      y_m: 2";
  const std::array<RigTextEdit, 1> edit{{{"back", kMount}}};
  EXPECT_EQ(editRigText(lastBlock, "mount", edit, ""),
            "cameras:\n  - name: back\n    mount:\n      " + kMount);
  const std::string added =
      editRigText("cameras:\n  - name: back\n    lens: {model: x}", "mount", edit, "");
  EXPECT_EQ(added, "cameras:\n  - name: back\n    lens: {model: x}\n    mount: " + kMount);

  const std::string quoted =
      "cameras:\n  - name: front\n    lens: {maker: O'Neil, model: pinhole,  # it's ours\n"
      "           note: 'a, b'}\n    mount: {x_m: 0}\n";
  const std::array<RigTextEdit, 1> lens{{{"front", "{model: fisheye}"}}};
  const std::string relensed = editRigText(quoted, "lens", lens, "");
  EXPECT_EQ(relensed,
            "cameras:\n  - name: front\n    lens: {model: fisheye}\n    mount: {x_m: 0}\n");
  EXPECT_EQ(YAML::Load(relensed)["cameras"][0]["mount"]["x_m"].as<double>(), 0);
}

TEST(RigTextEdit, WhatCannotBeEditedInPlaceIsNamed) {
  const std::array<RigTextEdit, 1> edit{{{"top", kMount}}};
  EXPECT_THAT([&] { editRigText(std::string(kRig), "mount", edit, ""); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("no camera 'top'")));
  const std::array<RigTextEdit, 1> front{{{"front", kMount}}};
  EXPECT_THAT([&] { editRigText(std::string(kRig), "our_part_number", front, ""); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  HasSubstr("camera 'front': its our_part_number is not a map")));
}

}  // namespace
}  // namespace surroundd::daemon
