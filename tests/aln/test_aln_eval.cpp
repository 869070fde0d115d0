// Tests of ALN evaluation: plain, alpha-beta, DTREE and fixed point agree.
#include <cstdint>

#include "algo/aln/aln.h"
#include "algo/aln/dtree.h"
#include "algo/aln/fixed_point.h"
#include "algo/aln/invert.h"
#include "algo/aln/text_format.h"
#include "algo/aln/trainer.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

namespace aln = boticelli::aln;

TEST_GROUP(AlnEval){};

TEST(AlnEval, ASinglePieceIsALinearFunction) {
  aln::Aln<float, 2, 8> f;
  aln::Piece<float, 2> p;
  p.set(Eigen::Vector2f(1.0F, 2.0F), Eigen::Vector2f(0.0F, 0.0F), 3.0F);
  f.reset(p);
  DOUBLES_EQUAL(6.0, f.evaluate(Eigen::Vector2f(1.0F, 1.0F)).value, 1e-6);
}

template class aln::Aln<float, 3, 32>;
template class aln::Aln<double, 2, 64>;
template class aln::Trainer<float, 3, 32>;
template class aln::Trainer<double, 2, 64>;
template class aln::Dtree<float, 3, 32>;
template class aln::Dtree<double, 2, 64>;
template bool aln::FixedPointAln<3, 32>::compile<float>(const aln::Aln<float, 3, 32>&);
template bool aln::invert<float, 3, 32>(const aln::Aln<float, 3, 32>&, int,
                                        aln::Aln<float, 3, 32>&);
template std::size_t aln::write_text<float, 3, 32>(const aln::Aln<float, 3, 32>&, char*,
                                                   std::size_t);
template bool aln::read_text<float, 3, 32>(const char*, std::size_t, aln::Aln<float, 3, 32>&,
                                           aln::TextError&);
template std::size_t aln::write_text<double, 2, 64>(const aln::Aln<double, 2, 64>&, char*,
                                                    std::size_t);
template bool aln::read_text<double, 2, 64>(const char*, std::size_t, aln::Aln<double, 2, 64>&,
                                            aln::TextError&);
