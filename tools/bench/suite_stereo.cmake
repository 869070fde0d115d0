# Suite "stereo": our frame-pair pipeline against OpenCV's goodFeaturesToTrack + pyramidal
# Lucas-Kanade on frames from the stereo tests' renderer, and the tracker on the Middlebury
# "Aloe" pair from OpenCV's sample data (opencv-doc). OpenCV and the samples are optional.
target_sources(boticelli-bench PRIVATE ${PROJECT_SOURCE_DIR}/tests/stereo/scene_renderer.cpp
                                       ${PROJECT_SOURCE_DIR}/tests/stereo/stereo_scenes.cpp)
target_include_directories(boticelli-bench PRIVATE ${PROJECT_SOURCE_DIR}/tests/stereo)
target_link_libraries(boticelli-bench PRIVATE boticelli_stereo boticelli_image)
find_package(OpenCV QUIET COMPONENTS core imgproc imgcodecs video)
if(OpenCV_FOUND)
  target_compile_definitions(boticelli-bench PRIVATE BOTICELLI_BENCH_HAVE_OPENCV=1)
  target_include_directories(boticelli-bench SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(boticelli-bench PRIVATE ${OpenCV_LIBS})
  find_path(BOTICELLI_OPENCV_SAMPLES_DIR aloeL.jpg
            PATHS /usr/share/doc/opencv-doc/examples/data /usr/share/opencv4/samples/data
            NO_DEFAULT_PATH)
  if(BOTICELLI_OPENCV_SAMPLES_DIR)
    target_sources(boticelli-bench PRIVATE ${PROJECT_SOURCE_DIR}/tests/stereo/aloe_pair.cpp)
    target_compile_definitions(boticelli-bench PRIVATE
      BOTICELLI_OPENCV_SAMPLES_DIR="${BOTICELLI_OPENCV_SAMPLES_DIR}")
  endif()
endif()
