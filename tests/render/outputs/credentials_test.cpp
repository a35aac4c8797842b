// Who may watch a served output (issue 50): the password file is read only when its owner alone
// may read it and it holds USER:PASSWORD; names and passwords are compared whole; only 127.0.0.0/8
// counts as this machine.

#include "render/outputs/credentials.hpp"

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/support/temp_dir.hpp"

namespace surroundd::render {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr auto kOwnerOnly =
    std::filesystem::perms::owner_read | std::filesystem::perms::owner_write;

TEST(Credentials, AreReadFromAFileOnlyItsOwnerMayRead) {
  const testing::TempDir dir;
  const auto file = dir.write("viewers.pw", "driver:correct horse battery\r\nignored\n");
  std::filesystem::permissions(file, kOwnerOnly);
  EXPECT_EQ(readCredentialsFile(file), (Credentials{"driver", "correct horse battery"}));

  std::filesystem::permissions(file, std::filesystem::perms::others_read,
                               std::filesystem::perm_options::add);
  EXPECT_THAT([&] { readCredentialsFile(file); },
              ThrowsMessage<std::runtime_error>(HasSubstr("(mode 604): chmod 600 it")));
  for (const char* text : {"driver\n", ":correct horse battery\n", "driver:short\n", ""}) {
    const auto bad = dir.write("bad.pw", text);
    std::filesystem::permissions(bad, kOwnerOnly);
    EXPECT_THAT([&] { readCredentialsFile(bad); },
                ThrowsMessage<std::runtime_error>(HasSubstr("bad.pw: expected USER:PASSWORD")))
        << text;
  }
  EXPECT_THAT([&] { readCredentialsFile(dir / "missing.pw"); },
              ThrowsMessage<std::runtime_error>(HasSubstr("missing.pw")));
}

TEST(Credentials, MatchOnlyWhole) {
  const Credentials expected{"driver", "correct horse battery"};
  EXPECT_TRUE(credentialsMatch(expected, "driver", "correct horse battery"));
  EXPECT_FALSE(credentialsMatch(expected, "driver", "correct horse batter"));
  EXPECT_FALSE(credentialsMatch(expected, "driver", "correct horse battery!"));
  EXPECT_FALSE(credentialsMatch(expected, "drive", "correct horse battery"));
  EXPECT_FALSE(credentialsMatch(expected, "", ""));
}

TEST(Credentials, OnlyLoopbackAddressesAreThisMachine) {
  EXPECT_TRUE(isLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(isLoopbackAddress("127.1.2.3"));
  EXPECT_FALSE(isLoopbackAddress("0.0.0.0"));
  EXPECT_FALSE(isLoopbackAddress("192.168.1.5"));
  EXPECT_FALSE(isLoopbackAddress("128.0.0.1"));
  EXPECT_FALSE(isLoopbackAddress("localhost"));
}

}  // namespace
}  // namespace surroundd::render
