// ExternalProcesses' pure parts: the argv from ProcCmd and ProcStartParams, $VAR expansion in
// ProcEnvParams, the log file's name.
#include "app/external_processes.h"

#include <gtest/gtest.h>

#include <map>

namespace convoy::app {
namespace {

TEST(ExternalProcesses, CommandAndParamsAreSplitAtWhitespace) {
  config::ExternalProcessConfig p;
  p.cmd = "  roslaunch  husky_world.launch\t";
  p.start_params = {"--a 1", "b", ""};
  EXPECT_EQ(command_words(p),
            (std::vector<std::string>{"roslaunch", "husky_world.launch", "--a", "1", "b"}));
}

TEST(ExternalProcesses, VariablesAreExpanded) {
  const std::map<std::string, std::string> env = {{"HOME", "/home/u"}, {"A_1", "x"}};
  auto lookup = [&](const std::string& name) {
    auto it = env.find(name);
    return it == env.end() ? std::string() : it->second;
  };
  EXPECT_EQ(expand_variables("$HOME/bin:${A_1}y", lookup), "/home/u/bin:xy");
  EXPECT_EQ(expand_variables("$UNSET-$A_1", lookup), "-x");
  EXPECT_EQ(expand_variables("cost $5 and $ and ${open", lookup), "cost $5 and $ and ${open");
  EXPECT_EQ(expand_variables("end$", lookup), "end$");
}

TEST(ExternalProcesses, LogNameIsTheProgramsBasenameAndIndex) {
  EXPECT_EQ(external_log_name("/usr/bin/python3", 0), "python3_0.log");
  EXPECT_EQ(external_log_name("./tools/run.sh", 3), "run.sh_3.log");
  EXPECT_EQ(external_log_name("..", 1), "proc_1.log");
}

}  // namespace
}  // namespace convoy::app
