// The files that install everytouchd as a service: the unit, the example configuration, the manual page.
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "service/config.h"
#include "service/daemon_options.h"
#include "support/file_contents.h"
#include "support/process.h"
#include "support/temp_dir.h"

namespace everytouch {
namespace {

using ::testing::HasSubstr;

TEST(SystemFiles, TheUnitVerifies) {
    // systemd-analyze exits 0 even on typos; it prints nothing only when everything is understood.
    const test::ProcessResult result =
        test::runProcess({"/usr/bin/systemd-analyze", "verify", "--man=no", BUILD_UNIT_FILE});
    EXPECT_EQ(result.exitCode, 0);
    EXPECT_EQ(result.out + result.err, "");
}

TEST(SystemFiles, TheUnitStaysHardened) {
    const test::ProcessResult result = test::runProcess(
        {"/usr/bin/systemd-analyze", "security", "--offline=true", "--threshold=30", BUILD_UNIT_FILE});
    EXPECT_EQ(result.exitCode, 0) << "exposure above 3.0:\n" << result.out;
    EXPECT_THAT(test::fileContents(BUILD_UNIT_FILE), HasSubstr("Type=notify"));
    EXPECT_THAT(test::fileContents(BUILD_UNIT_FILE), HasSubstr("ExecStart=" EVERYTOUCHD_PATH " --service"));
}

// The unit with its ExecStart= line's program left out.
std::string withoutProgram(const std::string& unit) {
    return std::regex_replace(unit, std::regex("ExecStart=\\S+"), "ExecStart=");
}

// Installs this build into a temporary root as `cmake --install --prefix PREFIX` with DESTDIR does.
void installInto(const test::TempDir& root, const std::string& prefix) {
    const test::ProcessResult result =
        test::runProcess({"/usr/bin/env", "DESTDIR=" + root.path().string(), CMAKE_COMMAND, "--install",
                          BUILD_DIR, "--prefix", prefix});
    ASSERT_EQ(result.exitCode, 0) << result.out << result.err;
}

TEST(SystemFiles, EveryFileIsInstalledWhereTheSystemLooksForItWhateverThePrefix) {
    for (const std::string prefix : {"/usr/local", "/usr"}) {
        SCOPED_TRACE("prefix " + prefix);
        test::TempDir root;
        installInto(root, prefix);
        const auto installed = [&](const std::string& path) { return root.path().string() + path; };
        EXPECT_TRUE(std::filesystem::is_regular_file(installed(prefix + "/sbin/everytouchd")));
        EXPECT_TRUE(std::filesystem::is_regular_file(installed(prefix + "/bin/everytouch-calib")));
        // The system bus reads policies here only; the daemon reads its configuration from the directory
        // the unit's ConfigurationDirectory= names.
        EXPECT_TRUE(std::filesystem::is_regular_file(
            installed("/usr/share/dbus-1/system.d/org.everytouch.Daemon1.conf")));
        EXPECT_TRUE(std::filesystem::is_regular_file(installed(service::kDefaultConfigPath)));
        EXPECT_EQ(std::string(service::kDefaultConfigPath), "/etc/everytouch/everytouchd.conf");
        EXPECT_TRUE(std::filesystem::is_regular_file(installed(SYSUSERS_DIR "/everytouch.conf")));
        EXPECT_TRUE(std::filesystem::is_regular_file(installed(UDEV_RULES_DIR "/70-everytouch.rules")));

        // The installed unit runs the installed binary, and otherwise is the unit the tests above verify.
        const std::string unit = test::fileContents(installed(UNIT_DIR "/everytouchd.service"));
        EXPECT_THAT(unit, HasSubstr("\nExecStart=" + prefix + "/sbin/everytouchd --service\n"));
        EXPECT_EQ(withoutProgram(unit), withoutProgram(test::fileContents(BUILD_UNIT_FILE)));
    }
}

// The keys the example shows commented out, as "[Section] Key".
std::set<std::string> commentedKeys(const std::string& example) {
    std::set<std::string> keys;
    std::istringstream lines(example);
    std::string section;
    std::smatch match;
    for (std::string line; std::getline(lines, line);) {
        if (std::regex_match(line, match, std::regex("\\[(\\w+)\\]")))
            section = match[1];
        else if (std::regex_match(line, match, std::regex("#(\\w+)=.*")))
            keys.insert("[" + section + "] " + std::string(match[1]));
    }
    return keys;
}

TEST(SystemFiles, TheExampleConfigurationAndTheManualDocumentEveryKey) {
    const std::string example = test::fileContents(EXAMPLE_CONFIG);
    const std::string manual = test::fileContents(DAEMON_MANUAL);
    std::set<std::string> known;
    for (const auto& [section, key] : service::configKeys()) {
        known.insert("[" + section + "] " + key);
        EXPECT_THAT(manual, HasSubstr("*[" + section + "] " + key + "=*"));
    }
    EXPECT_EQ(commentedKeys(example), known);
    // With every default uncommented it is still a valid configuration.
    test::TempDir dir;
    std::ofstream(dir / "everytouchd.conf") << std::regex_replace(example, std::regex("\\n#(\\w+=)"), "\n$1");
    const service::DaemonConfig config = service::loadConfig(dir / "everytouchd.conf", true);
    EXPECT_EQ(config, service::DaemonConfig());
}

}  // namespace
}  // namespace everytouch
