// CppUTest main shared by every test binary: installs MockSupportPlugin, runs all tests.
#include "CppUTest/CommandLineTestRunner.h"
#include "CppUTest/TestRegistry.h"
#include "CppUTestExt/MockSupportPlugin.h"

int main(int argc, char** argv) {
  MockSupportPlugin mock_plugin;
  TestRegistry::getCurrentRegistry()->installPlugin(&mock_plugin);
  return CommandLineTestRunner::RunAllTests(argc, argv);
}
