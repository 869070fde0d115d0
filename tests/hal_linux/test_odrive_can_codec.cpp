// Tests of the ODrive CAN Simple codec (every frame the base sends or accepts, and malformed
// ones) and of the differential-drive kinematics and odometry.
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "hal/codec/diff_drive.h"
#include "hal/codec/odrive_can_codec.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

namespace od = boticelli::codec::odrive;
using boticelli::codec::DiffDriveGeometry;
using boticelli::codec::DiffDriveOdometry;
using boticelli::codec::WheelTurns;

TEST_GROUP(OdriveCanFrames){};

TEST(OdriveCanFrames, TheIdIsTheNodeShiftedByFiveOrTheCommand) {
  CHECK_EQUAL(0x2CU, od::make_id(1, od::Command{0x0C}));
  CHECK_EQUAL(0x07U, od::make_id(0, od::Command::kSetAxisState));
  CHECK_EQUAL(0x7F8U, od::make_id(63, od::Command::kClearErrors));
  CHECK_EQUAL(63U, od::node_of(0x7F8));
  CHECK_EQUAL(0x18U, od::command_of(0x7F8));
}

TEST(OdriveCanFrames, SetAxisStateCarriesTheStateLittleEndian) {
  const od::CanFrame f = od::encode_set_axis_state(3, od::AxisState::kClosedLoopControl);
  CHECK_EQUAL(0x67U, f.id);
  CHECK_EQUAL(4, f.dlc);
  const std::uint8_t want[4] = {8, 0, 0, 0};
  MEMCMP_EQUAL(want, f.data.data(), 4);
}

TEST(OdriveCanFrames, SetControllerModeIsVelocityControlWithPassthroughInput) {
  const od::CanFrame f = od::encode_set_controller_mode(1, od::ControlMode::kVelocityControl,
                                                        od::InputMode::kPassthrough);
  CHECK_EQUAL(0x2BU, f.id);
  CHECK_EQUAL(8, f.dlc);
  const std::uint8_t want[8] = {2, 0, 0, 0, 1, 0, 0, 0};
  MEMCMP_EQUAL(want, f.data.data(), 8);
}

TEST(OdriveCanFrames, SetInputVelIsTwoLittleEndianFloats) {
  const od::CanFrame f = od::encode_set_input_vel(0, 1.0F, -2.0F);
  CHECK_EQUAL(0x0DU, f.id);
  // 1.0f = 0x3F800000, -2.0f = 0xC0000000
  const std::uint8_t want[8] = {0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x00, 0xC0};
  MEMCMP_EQUAL(want, f.data.data(), 8);
}

TEST(OdriveCanFrames, EstopClearErrorsAndTheEncoderRequestHaveNoPayloadToSpeakOf) {
  od::CanFrame f = od::encode_estop(2);
  CHECK_EQUAL(0x42U, f.id);
  CHECK_EQUAL(0, f.dlc);
  f = od::encode_clear_errors(2);
  CHECK_EQUAL(0x58U, f.id);
  CHECK_EQUAL(1, f.dlc);
  CHECK_EQUAL(0, f.data[0]);
  f = od::encode_encoder_request(2);
  CHECK_EQUAL(0x49U, f.id);
  CHECK_TRUE(f.remote);
}

TEST(OdriveCanFrames, AHeartbeatDecodesErrorAndState) {
  od::CanFrame f;
  f.id = od::make_id(1, od::Command::kHeartbeat);
  f.dlc = 8;
  f.data = {0x00, 0x08, 0x00, 0x00, 8, 0, 1, 0};
  od::Message m;
  CHECK(od::decode(f, m) == od::DecodeStatus::kOk);
  CHECK(m.command == od::Command::kHeartbeat);
  CHECK_EQUAL(1, m.node_id);
  CHECK_EQUAL(0x800U, m.heartbeat.axis_error);
  CHECK_EQUAL(8, m.heartbeat.axis_state);
  CHECK_TRUE(m.heartbeat.trajectory_done);
}

TEST(OdriveCanFrames, EncoderEstimatesRoundTrip) {
  od::EncoderEstimates e{12.5F, -3.25F};
  od::Message m;
  CHECK(od::decode(od::encode_encoder_estimates(5, e), m) == od::DecodeStatus::kOk);
  CHECK_EQUAL(5, m.node_id);
  CHECK_EQUAL(12.5F, m.encoder.pos_turns);
  CHECK_EQUAL(-3.25F, m.encoder.vel_turns_s);
}

TEST(OdriveCanFrames, EveryHostCommandDecodesToWhatWasEncoded) {
  od::Message m;
  CHECK(od::decode(od::encode_set_input_vel(4, 2.5F, 0.5F), m) == od::DecodeStatus::kOk);
  CHECK_EQUAL(2.5F, m.input_vel_turns_s);
  CHECK_EQUAL(0.5F, m.input_torque_ff_nm);
  CHECK(od::decode(od::encode_set_axis_state(4, od::AxisState::kIdle), m) == od::DecodeStatus::kOk);
  CHECK_EQUAL(1U, m.requested_state);
  CHECK(od::decode(od::encode_estop(4), m) == od::DecodeStatus::kOk);
  CHECK(m.command == od::Command::kEstop);
  CHECK(od::decode(od::encode_clear_errors(4), m) == od::DecodeStatus::kOk);
  CHECK(m.command == od::Command::kClearErrors);
  CHECK(od::decode(od::encode_set_controller_mode(4, od::ControlMode::kVelocityControl,
                                                  od::InputMode::kVelRamp),
                   m) == od::DecodeStatus::kOk);
  CHECK_EQUAL(2U, m.control_mode);
  CHECK_EQUAL(2U, m.input_mode);
}

TEST(OdriveCanFrames, AWrongLengthIsRejectedForEveryCommand) {
  od::Message m;
  od::CanFrame f = od::encode_heartbeat(1, {});
  f.dlc = 5;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
  f = od::encode_encoder_estimates(1, {});
  f.dlc = 4;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
  f = od::encode_set_axis_state(1, od::AxisState::kIdle);
  f.dlc = 8;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
  f = od::encode_estop(1);
  f.dlc = 1;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
  f = od::encode_set_input_vel(1, 0.0F);
  f.dlc = 7;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
  f = od::encode_set_controller_mode(1, od::ControlMode::kVelocityControl,
                                     od::InputMode::kPassthrough);
  f.dlc = 0;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
  f = od::encode_clear_errors(1);
  f.dlc = 2;
  CHECK(od::decode(f, m) == od::DecodeStatus::kWrongLength);
}

TEST(OdriveCanFrames, UnknownCommandsExtendedIdsAndBadDlcAreRejected) {
  od::Message m;
  od::CanFrame f;
  f.id = od::make_id(1, od::Command{0x1F});
  f.dlc = 8;
  CHECK(od::decode(f, m) == od::DecodeStatus::kUnknownCommand);
  STRCMP_EQUAL("unknown command id", od::to_string(od::decode(f, m)));
  f = od::encode_heartbeat(1, {});
  f.extended = true;
  CHECK(od::decode(f, m) == od::DecodeStatus::kExtendedId);
  f = od::encode_heartbeat(1, {});
  f.dlc = 9;
  CHECK(od::decode(f, m) == od::DecodeStatus::kBadDlc);
}

TEST(OdriveCanFrames, NonFiniteFloatsAreRejectedWithoutTouchingTheOutput) {
  od::Message m;
  m.encoder.pos_turns = 7.0F;
  od::CanFrame f = od::encode_encoder_estimates(1, {std::numeric_limits<float>::quiet_NaN(), 0.0F});
  CHECK(od::decode(f, m) == od::DecodeStatus::kNotFinite);
  CHECK_EQUAL(7.0F, m.encoder.pos_turns);
  f = od::encode_set_input_vel(1, std::numeric_limits<float>::infinity());
  CHECK(od::decode(f, m) == od::DecodeStatus::kNotFinite);
}

TEST(OdriveCanFrames, ANonFiniteVelocityIsRejectedAsMuchAsANonFinitePosition) {
  od::Message m;
  m.encoder.vel_turns_s = 7.0F;
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
        -std::numeric_limits<float>::infinity()}) {
    CHECK(od::decode(od::encode_encoder_estimates(1, {1.0F, bad}), m) ==
          od::DecodeStatus::kNotFinite);
    CHECK_EQUAL(7.0F, m.encoder.vel_turns_s);
    CHECK(od::decode(od::encode_set_input_vel(1, 0.5F, bad), m) == od::DecodeStatus::kNotFinite);
  }
}

TEST(OdriveCanFrames, ARemoteFrameIsARequestNotData) {
  od::Message m;
  CHECK(od::decode(od::encode_encoder_request(3), m) == od::DecodeStatus::kRemoteRequest);
  CHECK(m.command == od::Command::kGetEncoderEstimates);
}

TEST(OdriveCanFrames, ARemoteFrameOfAnyCommandIsNeverDecodedAsData) {
  // An RTR frame carries no payload even when its dlc says 8: a remote heartbeat must not
  // read as a healthy axis (or as an error) from whatever the data bytes hold.
  od::Message m;
  od::CanFrame f = od::encode_heartbeat(2, {0x800U, 8, 0, true});
  f.remote = true;
  m.heartbeat.axis_error = 5;
  CHECK(od::decode(f, m) == od::DecodeStatus::kRemoteRequest);
  CHECK(m.command == od::Command::kHeartbeat);
  CHECK_EQUAL(5U, m.heartbeat.axis_error);
  const od::CanFrame host[] = {od::encode_estop(2),
                               od::encode_set_axis_state(2, od::AxisState::kIdle),
                               od::encode_set_controller_mode(2, od::ControlMode::kVelocityControl,
                                                              od::InputMode::kPassthrough),
                               od::encode_set_input_vel(2, 1.0F), od::encode_clear_errors(2)};
  for (od::CanFrame h : host) {
    h.remote = true;
    CHECK(od::decode(h, m) == od::DecodeStatus::kRemoteRequest);
  }
}

TEST(OdriveCanFrames, DecodingDoesNotAllocate) {
  const od::CanFrame f = od::encode_encoder_estimates(1, {1.0F, 2.0F});
  od::Message m;
  od::DecodeStatus st = od::DecodeStatus::kBadDlc;
  CHECK_NO_ALLOCATION(st = od::decode(f, m));
  CHECK(st == od::DecodeStatus::kOk);
}

TEST_GROUP(DiffDrive) {
  DiffDriveGeometry g{0.1F, 0.5F, 1.0F, -1.0F};
};

TEST(DiffDrive, StraightAheadTurnsTheMirroredWheelsOppositeWays) {
  const WheelTurns w = boticelli::codec::body_to_wheels(1.0F, 0.0F, g);
  const double turns = 1.0 / (2.0 * std::numbers::pi * 0.1);
  DOUBLES_EQUAL(turns, w.left, 1e-5);
  DOUBLES_EQUAL(-turns, w.right, 1e-5);
}

TEST(DiffDrive, TurningInPlaceSpinsBothMotorsTheSameWay) {
  // ω = 1 rad/s, b = 0.5 m: the right wheel rolls forward at 0.25 m/s, the left back.
  const WheelTurns w = boticelli::codec::body_to_wheels(0.0F, 1.0F, g);
  const double turns = 0.25 / (2.0 * std::numbers::pi * 0.1);
  DOUBLES_EQUAL(-turns, w.left, 1e-5);
  DOUBLES_EQUAL(-turns, w.right, 1e-5);
}

TEST(DiffDrive, WheelsToBodyInvertsBodyToWheels) {
  float v = 0;
  float omega = 0;
  boticelli::codec::wheels_to_body(boticelli::codec::body_to_wheels(0.3F, -0.7F, g), g, v, omega);
  DOUBLES_EQUAL(0.3, v, 1e-5);
  DOUBLES_EQUAL(-0.7, omega, 1e-5);
}

TEST(DiffDrive, OdometryOfAFullCircleReturnsToTheStart) {
  DiffDriveOdometry odo(g);
  const float v = 0.5F;
  const float omega = 0.5F;  // radius 1 m, period 4π s
  const WheelTurns rate = boticelli::codec::body_to_wheels(v, omega, g);
  const int steps = 1000;
  const double period = 4.0 * std::numbers::pi;
  for (int i = 0; i <= steps; ++i) {
    const double t = period * i / steps;
    odo.update({static_cast<float>(static_cast<double>(rate.left) * t),
                static_cast<float>(static_cast<double>(rate.right) * t)});
    if (i == steps / 4) {  // a quarter circle: at (1, 1) facing +y
      DOUBLES_EQUAL(1.0, odo.x_m(), 1e-3);
      DOUBLES_EQUAL(1.0, odo.y_m(), 1e-3);
      DOUBLES_EQUAL(std::numbers::pi / 2, odo.yaw_rad(), 1e-4);
    }
  }
  DOUBLES_EQUAL(0.0, odo.x_m(), 1e-3);
  DOUBLES_EQUAL(0.0, odo.y_m(), 1e-3);
  DOUBLES_EQUAL(0.0, std::sin(odo.yaw_rad()), 1e-4);
}

TEST(DiffDrive, TheFirstSampleOnlySetsTheReference) {
  DiffDriveOdometry odo(g);
  odo.update({100.0F, -100.0F});  // arbitrary encoder offsets at start-up
  DOUBLES_EQUAL(0.0, odo.x_m(), 0.0);
  odo.update({101.0F, -101.0F});  // one turn forward on both wheels
  DOUBLES_EQUAL(2.0 * std::numbers::pi * 0.1, odo.x_m(), 1e-5);
  odo.reset_reference();
  odo.update({0.0F, 0.0F});  // a jump (ODrive rebooted) is not counted as motion
  DOUBLES_EQUAL(2.0 * std::numbers::pi * 0.1, odo.x_m(), 1e-5);
}

// A calibrated base: the right wheel 1% larger than the left (E_d = 1.01, mean radius 0.1 m)
// and an effective track of 0.505 m. A straight drive turns the smaller wheel more, and the
// odometry of those turns goes straight; a turn in place turns by ω·t on the effective track.
TEST(DiffDrive, ACalibratedBaseDrivesAndCountsByEachWheelsEffectiveRadiusAndTheEffectiveTrack) {
  DiffDriveGeometry c = g;
  c.track_width_m = 0.505F;
  c.left_scale = 2.0F / 2.01F;
  c.right_scale = 2.0F * 1.01F / 2.01F;
  const WheelTurns w = boticelli::codec::body_to_wheels(1.0F, 0.0F, c);
  DOUBLES_EQUAL(1.0 / (2.0 * std::numbers::pi * 0.1 * (2.0 / 2.01)), w.left, 1e-4);
  DOUBLES_EQUAL(-1.0 / (2.0 * std::numbers::pi * 0.1 * (2.02 / 2.01)), w.right, 1e-4);
  float v = 0;
  float omega = 0;
  boticelli::codec::wheels_to_body(boticelli::codec::body_to_wheels(0.3F, -0.7F, c), c, v, omega);
  DOUBLES_EQUAL(0.3, v, 1e-5);
  DOUBLES_EQUAL(-0.7, omega, 1e-5);
  DiffDriveOdometry odo(c);
  odo.update({0.0F, 0.0F});
  odo.update({w.left * 2.0F, w.right * 2.0F});  // 2 s straight at 1 m/s
  DOUBLES_EQUAL(2.0, odo.x_m(), 1e-4);
  DOUBLES_EQUAL(0.0, odo.yaw_rad(), 1e-5);
  const WheelTurns spin = boticelli::codec::body_to_wheels(0.0F, 1.0F, c);
  odo.update({w.left * 2.0F + spin.left, w.right * 2.0F + spin.right});  // 1 s at 1 rad/s
  DOUBLES_EQUAL(1.0, odo.yaw_rad(), 1e-4);
  DOUBLES_EQUAL(2.0, odo.x_m(), 1e-4);
}
