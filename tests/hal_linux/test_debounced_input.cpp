// Tests of DebouncedInput: polarity, lock-out debounce and the activation latch of GPIO inputs.
#include <cstdint>

#include "hal/codec/debounced_input.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::codec::DebouncedInput;

TEST_GROUP(DebouncedInput){};

TEST(DebouncedInput, AnActiveLowInputIsActiveWhenTheLineIsLow) {
  DebouncedInput in(true, 10000);
  in.reset(true, 0);  // pulled up: released
  CHECK_FALSE(in.active());
  in.on_edge(false, 50000);  // pressed: the line falls
  CHECK_TRUE(in.active());
  CHECK_TRUE(in.take_activation());
}

TEST(DebouncedInput, AnActiveHighInputFollowsTheLine) {
  DebouncedInput in(false, 10000);
  in.reset(false, 0);
  in.on_edge(true, 50000);
  CHECK_TRUE(in.active());
}

TEST(DebouncedInput, TheStartUpLevelIsNotAnActivation) {
  DebouncedInput in(false, 10000);
  in.reset(true, 0);
  CHECK_TRUE(in.active());
  CHECK_FALSE(in.take_activation());
}

TEST(DebouncedInput, APressActsAtOnceAndItsBouncesAreIgnored) {
  DebouncedInput in(false, 10000);
  in.reset(false, 0);
  in.on_edge(true, 100000);  // accepted at once: no debounce delay for an e-stop
  CHECK_TRUE(in.active());
  in.on_edge(false, 100500);  // bounce inside the 10 ms lock-out
  in.on_edge(true, 101000);
  in.on_edge(false, 101500);
  in.on_edge(true, 102000);
  CHECK_TRUE(in.active());
  in.settle(120000);
  CHECK_TRUE(in.active());  // the last raw level was active: still pressed
  CHECK_TRUE(in.take_activation());
  CHECK_FALSE(in.take_activation());  // one press, one activation
}

TEST(DebouncedInput, AReleaseInsideTheLockOutIsAppliedOnceItHasPassed) {
  DebouncedInput in(false, 10000);
  in.reset(false, 0);
  in.on_edge(true, 100000);
  in.on_edge(false, 105000);
  CHECK_TRUE(in.active());
  in.settle(109999);
  CHECK_TRUE(in.active());
  in.settle(110000);
  CHECK_FALSE(in.active());
}

TEST(DebouncedInput, AShortPressBetweenTwoPollsIsNotMissed) {
  DebouncedInput in(true, 10000);
  in.reset(true, 0);
  in.on_edge(false, 100000);  // pressed ...
  in.on_edge(true, 103000);   // ... and released before the executive polls
  in.settle(120000);
  CHECK_FALSE(in.active());
  CHECK_TRUE(in.take_activation());
}

TEST(DebouncedInput, TwoSeparatePressesAreTwoActivations) {
  DebouncedInput in(false, 10000);
  in.reset(false, 0);
  in.on_edge(true, 100000);
  CHECK_TRUE(in.take_activation());
  in.on_edge(false, 200000);
  in.on_edge(true, 300000);
  CHECK_TRUE(in.take_activation());
}

TEST(DebouncedInput, APolledLevelReconcilesLostEvents) {
  DebouncedInput in(false, 10000);
  in.reset(false, 0);
  in.on_level(true, 100000);
  CHECK_TRUE(in.active());
  CHECK_TRUE(in.take_activation());
}

TEST(DebouncedInput, TheCyclicCallsDoNotAllocate) {
  DebouncedInput in(false, 10000);
  in.reset(false, 0);
  bool got = false;
  CHECK_NO_ALLOCATION(in.on_edge(true, 100000); in.settle(200000); got = in.take_activation());
  CHECK_TRUE(got);
}

TEST(DebouncedInput, OutputPolarityIsAppliedByPhysicalLevel) {
  CHECK_TRUE(boticelli::codec::physical_level(true, false));
  CHECK_FALSE(boticelli::codec::physical_level(true, true));
  CHECK_TRUE(boticelli::codec::physical_level(false, true));
}
