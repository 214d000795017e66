// The files that install everytouchd as a service: the unit, the example configuration, the manual page.
#include <filesystem>
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
        {"/usr/bin/systemd-analyze", "security", "--offline=true", "--threshold=20", BUILD_UNIT_FILE});
    EXPECT_EQ(result.exitCode, 0) << "exposure above 2.0:\n" << result.out;
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

TEST(SystemFiles, TheDebianPackageHoldsTheInstallAndLintianFindsNoError) {
    test::TempDir out;
    const test::ProcessResult packed = test::runProcess(
        {CPACK_COMMAND, "-G", "DEB", "--config", BUILD_DIR "/CPackConfig.cmake", "-B", out.path()});
    ASSERT_EQ(packed.exitCode, 0) << packed.out << packed.err;
    std::filesystem::path deb;
    for (const auto& entry : std::filesystem::directory_iterator(out.path()))
        if (entry.path().extension() == ".deb")
            deb = entry.path();
    ASSERT_FALSE(deb.empty()) << packed.out;

    const test::ProcessResult contents = test::runProcess({"/usr/bin/dpkg-deb", "--contents", deb});
    for (const std::string path :
         {"./usr/sbin/everytouchd", "./usr/bin/everytouch-calib",
          "./usr/share/dbus-1/system.d/org.everytouch.Daemon1.conf", "./etc/everytouch/everytouchd.conf",
          "." UNIT_DIR "/everytouchd.service", "./usr/share/doc/everytouch/copyright",
          "./usr/share/man/man8/everytouchd.8.gz"})
        EXPECT_THAT(contents.out, HasSubstr(" " + path + "\n"));
    const test::ProcessResult control = test::runProcess({"/usr/bin/dpkg-deb", "--field", deb, "Depends"});
    EXPECT_THAT(control.out, HasSubstr("libevdev2"));
    EXPECT_THAT(control.out, HasSubstr("libsystemd0"));

    // Debian's own checker: warnings are allowed (a tool without a manual page), errors are not.
    const test::ProcessResult lint = test::runProcess({"/usr/bin/lintian", "--tag-display-limit", "0", deb});
    EXPECT_EQ(lint.exitCode, 0) << lint.out << lint.err;
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

TEST(SystemFiles, TheManualPagesHaveNoMandocWarning) {
    int pages = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::string(BUILD_DIR) + "/man")) {
        if (!std::regex_match(entry.path().filename().string(), std::regex(".+\\.[158]")))
            continue;
        ++pages;
        // Style remarks (long source lines, a lower-case title) are scdoc's and change nothing on the page.
        const test::ProcessResult result =
            test::runProcess({"/usr/bin/mandoc", "-T", "lint", "-W", "warning", entry.path().string()});
        EXPECT_EQ(result.exitCode, 0) << entry.path();
        EXPECT_EQ(result.out + result.err, "") << entry.path();
    }
    EXPECT_EQ(pages, 3);
}

TEST(SystemFiles, TheExampleConfigurationAndTheManualDocumentEveryKey) {
    const std::string example = test::fileContents(EXAMPLE_CONFIG);
    const std::string manual = test::fileContents(CONFIG_MANUAL);
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
