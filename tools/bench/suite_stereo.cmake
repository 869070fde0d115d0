# Suite "stereo": our frame-pair pipeline against OpenCV's goodFeaturesToTrack + pyramidal
# Lucas-Kanade on frames from the stereo tests' renderer. OpenCV is optional.
target_sources(boticelli-bench PRIVATE ${PROJECT_SOURCE_DIR}/tests/stereo/scene_renderer.cpp
                                       ${PROJECT_SOURCE_DIR}/tests/stereo/stereo_scenes.cpp)
target_include_directories(boticelli-bench PRIVATE ${PROJECT_SOURCE_DIR}/tests/stereo)
target_link_libraries(boticelli-bench PRIVATE boticelli_stereo boticelli_image)
find_package(OpenCV QUIET COMPONENTS core imgproc video)
if(OpenCV_FOUND)
  target_compile_definitions(boticelli-bench PRIVATE BOTICELLI_BENCH_HAVE_OPENCV=1)
  target_include_directories(boticelli-bench SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(boticelli-bench PRIVATE ${OpenCV_LIBS})
endif()
