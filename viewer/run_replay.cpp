#include "viewer/run_replay.hpp"

#include "viewer/recorded_run.hpp"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkCommand.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderer.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <cstdio>
#include <memory>

namespace kerf {

namespace {

/// Distinct line colours for up to six runs (then they repeat).
constexpr unsigned char run_colours[6][3] = {{31, 119, 180}, {214, 39, 40}, {44, 160, 44},
                                             {255, 127, 14}, {148, 103, 189}, {140, 86, 75}};

vtkSmartPointer<vtkTable> curve_table(const std::string& name, const std::vector<double>& u_mm,
                                      const std::vector<double>& f) {
  auto table = vtkSmartPointer<vtkTable>::New();
  auto x = vtkSmartPointer<vtkDoubleArray>::New();
  x->SetName("tool displacement [mm]");
  auto y = vtkSmartPointer<vtkDoubleArray>::New();
  y->SetName(name.c_str());
  for (std::size_t i = 0; i < u_mm.size(); ++i) {
    x->InsertNextValue(u_mm[i]);
    y->InsertNextValue(f[i]);
  }
  table->AddColumn(x);
  table->AddColumn(y);
  return table;
}

/// The replay's state: runs, their views, the chart with one curve and one marker per run.
struct Replay {
  std::vector<std::unique_ptr<RecordedRun>> runs;
  std::vector<std::unique_ptr<BodyView>> views;
  std::vector<vtkSmartPointer<vtkTable>> markers;
  vtkSmartPointer<vtkChartXY> chart;
  double colour_max = 0.0;
  Colouring colouring = Colouring::displacement;
  bool text = true;

  void show(double t) {
    double largest = 0.0;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      runs[i]->show(t, *views[i], text);
      largest = std::max(largest, views[i]->data_maximum());
    }
    // One colour scale for all runs, so equal colours mean equal values side by side; the
    // automatic one no lower than the live view's floors (FrameView: 0.1 mm, 1 kPa), so that a
    // body at rest is one colour, not round-off noise spread over the whole scale.
    const double lowest = colouring == Colouring::displacement ? 1e-4 : 1e3;
    const double top = colour_max > 0.0 ? colour_max : std::max(largest, lowest);
    for (auto& v : views) v->set_colour_range(top);
    for (std::size_t i = 0; i < markers.size(); ++i) {
      const std::size_t k = runs[i]->curve_index(t);
      markers[i]->SetValue(0, 0, runs[i]->curve_displacement()[k] * 1e3);
      markers[i]->SetValue(0, 1, runs[i]->curve_force()[k]);
      markers[i]->Modified();
    }
    if (chart) chart->RecalculateBounds();
  }
};

struct SliderCallback : vtkCommand {
  static SliderCallback* New() { return new SliderCallback; }
  void Execute(vtkObject* caller, unsigned long, void*) override {
    auto* widget = static_cast<vtkSliderWidget*>(caller);
    replay->show(static_cast<vtkSliderRepresentation*>(widget->GetRepresentation())->GetValue());
  }
  Replay* replay = nullptr;
};

} // namespace

void replay_runs(const ReplaySettings& settings) {
  if (settings.runs.empty()) throw std::invalid_argument("viewer: no run directory to replay");
  Replay replay;
  replay.colour_max = settings.colour_max;
  replay.colouring = settings.colouring;
  replay.text = settings.text;
  double duration = 0.0, force_max = 0.1;
  Eigen::AlignedBox3d bounds;
  for (const auto& dir : settings.runs) {
    std::printf("loading %s ...\n", dir.c_str());
    std::fflush(stdout);
    replay.runs.push_back(std::make_unique<RecordedRun>(dir, settings.frames));
    const RecordedRun& r = *replay.runs.back();
    duration = std::max(duration, r.duration());
    bounds.extend(r.bounds());
    for (double f : r.curve_force()) force_max = std::max(force_max, f);
    if (!r.has_series())
      std::printf("  %s re-stepped: force differs from the recorded profile by at most %.3g N\n", r.label().c_str(),
                  r.replay_force_difference());
  }

  ViewWindow window(settings.window, static_cast<int>(replay.runs.size()), settings.chart);
  for (std::size_t i = 0; i < replay.runs.size(); ++i) {
    const Scene& scene = replay.runs[i]->scene();
    std::vector<ToolGlyph> glyphs;
    for (const Tool& t : scene.tools)
      glyphs.push_back({t.kind == Tool::Kind::blade, t.radius, t.blade});
    replay.views.push_back(std::make_unique<BodyView>(window.body_renderer(static_cast<int>(i)), settings.colouring, glyphs));
    replay.views.back()->set_overlay_visible(settings.overlay);
    replay.views.back()->set_legend_visible(settings.text);
    replay.views.back()->set_force_scale(0.25 * bounds.sizes().norm() / force_max);
  }
  frame_camera(window.camera(), bounds, settings.camera, window.body_aspect());

  if (settings.chart) {
    // The linked chart: each run's force-displacement curve and a marker at the shown time.
    replay.chart = vtkSmartPointer<vtkChartXY>::New();
    replay.chart->SetShowLegend(true);
    replay.chart->GetAxis(vtkAxis::BOTTOM)->SetTitle("tool displacement [mm]");
    replay.chart->GetAxis(vtkAxis::LEFT)->SetTitle("|F| [N]");
    for (std::size_t i = 0; i < replay.runs.size(); ++i) {
      const RecordedRun& r = *replay.runs[i];
      std::vector<double> u_mm;
      for (double u : r.curve_displacement()) u_mm.push_back(u * 1e3);
      auto table = curve_table(r.label(), u_mm, r.curve_force());
      const unsigned char* c = run_colours[i % 6];
      vtkPlot* line = replay.chart->AddPlot(vtkChart::LINE);
      line->SetInputData(table, 0, 1);
      line->SetColor(c[0], c[1], c[2], 255);
      line->SetWidth(2.0);
      auto marker = curve_table(r.label() + " now", {0.0}, {0.0});
      vtkPlot* point = replay.chart->AddPlot(vtkChart::POINTS);
      point->SetInputData(marker, 0, 1);
      point->SetColor(c[0], c[1], c[2], 255);
      point->SetLegendVisibility(false);
      if (auto* p = vtkPlotPoints::SafeDownCast(point)) {
        p->SetMarkerStyle(vtkPlotPoints::CIRCLE);
        p->SetMarkerSize(12.0);
      }
      replay.markers.push_back(marker);
    }
    auto context = vtkSmartPointer<vtkContextActor>::New();
    context->GetScene()->AddItem(replay.chart);
    window.chart_renderer()->AddActor(context);
    context->GetScene()->SetRenderer(window.chart_renderer());
  }

  const double at = settings.at >= 0.0 ? std::min(settings.at, duration) : duration;
  replay.show(at);
  if (!settings.screenshot.empty()) {
    window.write_png(settings.screenshot);
    return;
  }

  // The shared time slider along the top of the chart strip.
  auto slider_rep = vtkSmartPointer<vtkSliderRepresentation2D>::New();
  slider_rep->SetMinimumValue(0.0);
  slider_rep->SetMaximumValue(duration);
  slider_rep->SetValue(at);
  slider_rep->SetTitleText("time [s]");
  slider_rep->GetPoint1Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  const double slider_y = settings.chart ? 0.32 : 0.05;
  slider_rep->GetPoint1Coordinate()->SetValue(0.1, slider_y);
  slider_rep->GetPoint2Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  slider_rep->GetPoint2Coordinate()->SetValue(0.9, slider_y);
  slider_rep->GetTitleProperty()->SetColor(0.0, 0.0, 0.0);
  slider_rep->GetLabelProperty()->SetColor(0.0, 0.0, 0.0);
  auto slider = vtkSmartPointer<vtkSliderWidget>::New();
  slider->SetInteractor(window.interactor());
  slider->SetRepresentation(slider_rep);
  slider->SetAnimationModeToAnimate();
  slider->EnabledOn();
  auto callback = vtkSmartPointer<SliderCallback>::New();
  callback->replay = &replay;
  slider->AddObserver(vtkCommand::InteractionEvent, callback);

  bool playing = false;
  const double period = 1.0 / 30.0;
  window.run(
      [&] {
        if (playing) {
          double t = slider_rep->GetValue() + period;
          if (t > duration) t = 0.0;
          slider_rep->SetValue(t);
          replay.show(t);
          window.render();
        }
        return true;
      },
      period,
      [&](const std::string& key) {
        if (key == "space") playing = !playing;
        if (key == "o")
          for (auto& v : replay.views) v->set_overlay_visible(!v->overlay_visible());
        window.render();
      });
}

} // namespace kerf
