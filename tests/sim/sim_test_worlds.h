// Helpers for the sim tests: paths of the shipped worlds and small worlds written inline.
#pragma once

#include <cstdio>
#include <string>

namespace boticelli::hal::sim::test {

inline std::string world_path(const char* name) {
  return std::string(BOTICELLI_WORLDS_DIR) + "/" + name + ".sdf";
}

inline constexpr const char* kShippedWorlds[] = {"thesis_room",
                                                 "cylindrical_room",
                                                 "cylindrical_room_offcentre",
                                                 "rectangular_room",
                                                 "corridor",
                                                 "box_in_cylindrical_room",
                                                 "box_in_rectangular_room",
                                                 "l_shaped_room",
                                                 "two_rooms_doorway",
                                                 "cluttered_room"};

// A world with the robot at the origin facing +x, the target on a paper box, and `models`.
inline std::string small_world(const std::string& models, const char* robot_pose = "0 0 0 0 0 0") {
  return std::string(
             "<sdf version=\"1.6\" xmlns:boticelli=\"urn:boticelli:sdf\">\n"
             "<world name=\"t\">\n"
             "<include><uri>model://boticelli</uri><pose>") +
         robot_pose +
         "</pose></include>\n"
         "<model name=\"target\"><pose>-4 0 1 0 0 0</pose><link name=\"l\"><visual name=\"v\">"
         "<geometry><box><size>0.01 0.3 0.3</size></box></geometry>"
         "<boticelli:pattern>paper</boticelli:pattern>"
         "<boticelli:target face=\"+x\" size=\"0.2\"/></visual></link></model>\n" +
         models + "</world>\n</sdf>\n";
}

inline std::string box_model(const char* name, const char* pose, const char* size) {
  return std::string("<model name=\"") + name + "\"><pose>" + pose +
         "</pose><link name=\"l\"><visual name=\"v\"><geometry><box><size>" + size +
         "</size></box></geometry></visual></link></model>\n";
}

}  // namespace boticelli::hal::sim::test
