// Tests of the evidence sensor model's closed forms (Eqs 3.7, 3.8).
#include "algo/evidence/sensor_model.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::evidence;

TEST_GROUP(SensorModel){};

TEST(SensorModel, EvidenceFallsWithTheSquareOfTheMatchError) {
  DOUBLES_EQUAL(1.0, evidence_from_match_error(0.0F, 100.0F), 1e-6);
  DOUBLES_EQUAL(0.75, evidence_from_match_error(50.0F, 100.0F), 1e-6);
  DOUBLES_EQUAL(0.19, evidence_from_match_error(90.0F, 100.0F), 1e-5);
  DOUBLES_EQUAL(0.0, evidence_from_match_error(100.0F, 100.0F), 1e-6);
  DOUBLES_EQUAL(0.0, evidence_from_match_error(250.0F, 100.0F), 1e-6);
}

TEST(SensorModel, RangeErrorMatchesTheThesisExample) {
  DOUBLES_EQUAL(0.385, range_error_m(1.0F, 0.028F, 150.0F), 0.001);
  DOUBLES_EQUAL(0.1, model_range_error_m(1.0F), 1e-6);
}
