# Suite "render": the sim board's ray-cast camera on the shipped worlds.
target_link_libraries(boticelli-bench PRIVATE boticelli_hal_sim boticelli_stereo)
target_compile_definitions(boticelli-bench PRIVATE
  BOTICELLI_WORLDS_DIR="${PROJECT_SOURCE_DIR}/boards/sim/worlds")
