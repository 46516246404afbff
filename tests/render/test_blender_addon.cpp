// The Blender add-on (tools/blender/karst_import.py, issue 14) imports a run's surface frames
// with their materials. Skipped, and said so, where Blender is not installed.
#include "support/files.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace karst {
namespace {

namespace fs = std::filesystem;

TEST(BlenderAddon, ImportsTheSurfacesOfARun) {
    if (std::system("command -v blender > /dev/null 2>&1") != 0)
        GTEST_SKIP() << "Blender is not installed (apt-get install blender): the add-on is not "
                        "tested";
    const test::TempDir dir("blender");
    const fs::path out = dir.path / "out";
    ASSERT_EQ(test::exit_code_of(std::string(KARST_BINARY) + " run " + KARST_SOURCE_DIR +
                                 "/scenes/cave_soak.json --quiet --end-time 0.05 --fps 20 --out " +
                                 out.string()),
              0);
    const fs::path blend = dir.path / "imported.blend";
    std::string err;
    const int code = test::exit_code_of(
        std::string("blender --background --factory-startup --python-exit-code 1 --python ") +
            KARST_SOURCE_DIR + "/tools/blender/karst_import.py -- " + out.string() + " --save " +
            blend.string(),
        &err);
    EXPECT_EQ(code, 0) << err;
    EXPECT_EQ(err.find("Error"), std::string::npos) << err;
    EXPECT_TRUE(fs::exists(blend));
}

}  // namespace
}  // namespace karst
