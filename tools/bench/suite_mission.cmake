# Suite "mission": both world sets (the shipped ones and tests/worlds), runs in parallel threads.
find_package(Threads REQUIRED)
target_link_libraries(boticelli-bench PRIVATE Threads::Threads)
target_compile_definitions(boticelli-bench PRIVATE
  BOTICELLI_TEST_WORLDS_DIR="${PROJECT_SOURCE_DIR}/tests/worlds")
