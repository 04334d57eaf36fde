// The diffuse term's form (model/diffuse_form.h): the Fresnel transmission against known values,
// the factor's normalisation, clamp and sign, and the gatherer storing it in Sample::d.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fit/diffuse_choice.h"
#include "model/diffuse_form.h"

namespace vbrdf {
namespace {

TEST(DiffuseForm, TransmissionMatchesFresnelForGlass) {
  // Unpolarised Fresnel reflectance of n = 1.5: 0.04 head-on, 0.0892 at 60 degrees, 1 at grazing.
  EXPECT_NEAR(coat_transmission(1.0f), 0.96f, 1e-5f);
  EXPECT_NEAR(coat_transmission(0.5f), 1.0f - 0.0892f, 5e-4f);
  EXPECT_NEAR(coat_transmission(0.0f), 0.0f, 1e-6f);
  EXPECT_NEAR(coat_transmission(2.0f), coat_transmission(1.0f), 1e-7f);  // clamped
  EXPECT_NEAR(coat_transmission(-1.0f), 0.0f, 1e-6f);
  for (float c = 0.0f; c < 1.0f; c += 0.05f) EXPECT_LE(coat_transmission(c), coat_transmission(c + 0.05f)) << c;
}

TEST(DiffuseForm, LambertIsTheCosineAndCoatedDimsAtGrazingAngles) {
  for (float nl : {-0.5f, 0.0f, 0.1f, 0.7f, 1.0f}) EXPECT_EQ(diffuse_factor(DiffuseForm::Lambert, nl, 0.3f), nl);
  EXPECT_NEAR(diffuse_factor(DiffuseForm::Coated, 1.0f, 1.0f), 1.0f, 1e-6f);  // normalised head-on
  // Light side and view side are the same curve (reciprocity).
  EXPECT_NEAR(diffuse_factor(DiffuseForm::Coated, 0.4f, 1.0f) / 0.4f, diffuse_factor(DiffuseForm::Coated, 1.0f, 0.4f),
              1e-6f);
  float previous = 2.0f;
  for (float nl = 1.0f; nl > 0.02f; nl -= 0.05f) {
    const float ratio = diffuse_factor(DiffuseForm::Coated, nl, 1.0f) / nl;
    EXPECT_LE(ratio, previous + 1e-6f) << nl;
    EXPECT_GT(ratio, 0.0f) << nl;
    previous = ratio;
  }
  EXPECT_LT(diffuse_factor(DiffuseForm::Coated, 0.2f, 1.0f) / 0.2f, 0.8f);  // grazing light really dims
}

TEST(DiffuseForm, ViewSideIsClampedAndSignAndFinitenessKept) {
  const float at_clamp = diffuse_factor(DiffuseForm::Coated, 0.8f, kCoatMinCosine);
  EXPECT_EQ(diffuse_factor(DiffuseForm::Coated, 0.8f, 0.05f), at_clamp);
  EXPECT_EQ(diffuse_factor(DiffuseForm::Coated, 0.8f, -1.0f), at_clamp);
  EXPECT_GT(at_clamp, 0.5f * 0.8f);  // never near 0 for a lit sample
  EXPECT_EQ(diffuse_factor(DiffuseForm::Coated, -0.3f, 0.9f), -0.3f);  // attached shadow keeps its sign
  EXPECT_EQ(diffuse_factor(DiffuseForm::Coated, 0.0f, 0.9f), 0.0f);
  EXPECT_TRUE(std::isfinite(diffuse_factor(DiffuseForm::Coated, 1e-30f, 1.0f)));
  EXPECT_TRUE(std::isfinite(diffuse_factor(DiffuseForm::Coated, 1.0f, std::numeric_limits<float>::max())));
}

// The coat is crossed once on the way in and once on the way out by the same curve, so d / N.L is
// symmetric in N.L and N.E (reciprocity), also below the clamp: a light-side term without the
// view side's clamp made grazing light 40 % darker than grazing view (spot: the fitted albedo took
// it in, and another camera disagreed).
TEST(DiffuseForm, CoatedFactorIsReciprocalInLightAndView) {
  for (float a = 0.02f; a <= 1.0f; a += 0.07f)
    for (float b = 0.02f; b <= 1.0f; b += 0.07f)
      EXPECT_NEAR(diffuse_factor(DiffuseForm::Coated, a, b) / a, diffuse_factor(DiffuseForm::Coated, b, a) / b, 1e-6f)
          << "N.L " << a << ", N.E " << b;
  // Below the clamp the light side stays at its value at the clamp, as the view side does.
  EXPECT_FLOAT_EQ(diffuse_factor(DiffuseForm::Coated, 0.05f, 1.0f) / 0.05f,
                  diffuse_factor(DiffuseForm::Coated, kCoatMinCosine, 1.0f) / kCoatMinCosine);
}

TEST(DiffuseForm, FormsPerVertexFallBackToTheUniformOne) {
  const DiffuseForms uniform = DiffuseForms::everywhere(DiffuseForm::Coated);
  EXPECT_FALSE(uniform.varies());
  EXPECT_EQ(uniform.at(12345), DiffuseForm::Coated);
  EXPECT_EQ(describe_diffuse_forms(uniform), "coated");
  const DiffuseForms map{DiffuseForm::Lambert, std::make_shared<std::vector<uint8_t>>(std::vector<uint8_t>{1, 0, 1})};
  EXPECT_TRUE(map.varies());
  EXPECT_EQ(map.at(0), DiffuseForm::Coated);
  EXPECT_EQ(map.at(1), DiffuseForm::Lambert);
  EXPECT_EQ(map.at(3), DiffuseForm::Lambert);  // beyond the map: the uniform form
  EXPECT_EQ(describe_diffuse_forms(map), "coated on 2 of 3 vertices, lambert elsewhere");
}

TEST(DiffuseForm, NamesRoundTrip) {
  DiffuseForm f = DiffuseForm::Lambert;
  EXPECT_TRUE(parse_diffuse_form(diffuse_form_name(DiffuseForm::Coated), f));
  EXPECT_EQ(f, DiffuseForm::Coated);
  EXPECT_TRUE(parse_diffuse_form(diffuse_form_name(DiffuseForm::Lambert), f));
  EXPECT_EQ(f, DiffuseForm::Lambert);
  EXPECT_FALSE(parse_diffuse_form("oren-nayar", f));
}

} // namespace
} // namespace vbrdf
