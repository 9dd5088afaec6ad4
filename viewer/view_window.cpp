#include "viewer/view_window.hpp"

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkWindowToImageFilter.h>

#include <X11/Xlib.h>

#include <cstdlib>
#include <stdexcept>

namespace kerf {

std::optional<CameraView> camera_view_from_string(std::string_view name) {
  if (name == "oblique") return CameraView::oblique;
  if (name == "front") return CameraView::front;
  return std::nullopt;
}

void require_display() {
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name)
    throw std::runtime_error("viewer: no X display (DISPLAY is unset); off screen, run under Xvfb: "
                             "xvfb-run -a -s \"-screen 0 1600x1200x24\" kerf view ...");
  Display* display = XOpenDisplay(name);
  if (!display)
    throw std::runtime_error(std::string("viewer: cannot open X display \"") + name +
                             "\"; off screen, run under Xvfb: xvfb-run -a kerf view ...");
  XCloseDisplay(display);
}

void frame_camera(vtkCamera* camera, const Eigen::AlignedBox3d& box, CameraView view, double aspect) {
  const Eigen::Vector3d c = box.center();
  const Eigen::Vector3d s = box.sizes();
  const double radius = 0.5 * s.norm();
  const Eigen::Vector3d direction =
      view == CameraView::front ? Eigen::Vector3d(0.0, -1.0, 0.0) : Eigen::Vector3d(0.9, -1.6, 1.1).normalized();
  const double distance = 4.0 * radius + 1e-3;
  const Eigen::Vector3d position = c + distance * direction;
  camera->SetFocalPoint(c.x(), c.y(), c.z());
  camera->SetPosition(position.x(), position.y(), position.z());
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->ParallelProjectionOn();
  // Half the visible height: the box's extent on the image plane (front: its x-z rectangle;
  // oblique: its bounding sphere), widened by 10%.
  const double half_height = view == CameraView::front ? std::max(0.5 * s.z(), 0.5 * s.x() / aspect)
                                                       : std::max(radius, radius / aspect);
  camera->SetParallelScale(1.1 * half_height);
  camera->SetClippingRange(std::max(1e-6, distance - 2.0 * radius), distance + 2.0 * radius);
}

ViewWindow::ViewWindow(const ViewWindowSettings& settings, int columns, bool chart) : m_settings(settings) {
  if (columns < 1) throw std::invalid_argument("viewer: at least one body to show");
  require_display();
  m_window = vtkSmartPointer<vtkRenderWindow>::New();
  m_window->SetSize(settings.width, settings.height);
  m_window->SetWindowName(settings.title.c_str());
  m_window->SetMultiSamples(0); // identical pixels run to run (the tests compare screenshots)
  if (settings.offscreen) m_window->SetOffScreenRendering(1);
  const double bottom = chart ? 0.3 : 0.0;
  auto camera = vtkSmartPointer<vtkCamera>::New();
  for (int i = 0; i < columns; ++i) {
    auto r = vtkSmartPointer<vtkRenderer>::New();
    r->SetViewport(static_cast<double>(i) / columns, bottom, static_cast<double>(i + 1) / columns, 1.0);
    r->SetBackground(1.0, 1.0, 1.0);
    r->SetActiveCamera(camera);
    m_window->AddRenderer(r);
    m_bodies.push_back(r);
  }
  if (chart) {
    m_chart = vtkSmartPointer<vtkRenderer>::New();
    m_chart->SetViewport(0.0, 0.0, 1.0, bottom);
    m_chart->SetBackground(1.0, 1.0, 1.0);
    m_window->AddRenderer(m_chart);
  }
  if (!settings.offscreen) {
    m_interactor = vtkSmartPointer<vtkRenderWindowInteractor>::New();
    m_interactor->SetRenderWindow(m_window);
    auto style = vtkSmartPointer<vtkInteractorStyleTrackballCamera>::New();
    m_interactor->SetInteractorStyle(style);
  }
}

ViewWindow::~ViewWindow() = default;

vtkCamera* ViewWindow::camera() const { return m_bodies.front()->GetActiveCamera(); }

double ViewWindow::body_aspect() const {
  const double* v = m_bodies.front()->GetViewport();
  return (v[2] - v[0]) * m_settings.width / ((v[3] - v[1]) * m_settings.height);
}

void ViewWindow::render() { m_window->Render(); }

void ViewWindow::write_png(const std::filesystem::path& file) {
  m_window->Render();
  auto image = vtkSmartPointer<vtkWindowToImageFilter>::New();
  image->SetInput(m_window);
  image->SetInputBufferTypeToRGB();
  image->ReadFrontBufferOff();
  image->Update();
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->SetFileName(file.c_str());
  writer->SetInputConnection(image->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0 || !std::filesystem::exists(file))
    throw std::runtime_error("viewer: could not write " + file.string());
}

namespace {

struct Callbacks {
  const std::function<bool()>* tick;
  const std::function<void(const std::string&)>* key;
  vtkRenderWindowInteractor* interactor;
};

void on_timer(vtkObject*, unsigned long, void* data, void*) {
  auto* c = static_cast<Callbacks*>(data);
  if (!(*c->tick)()) c->interactor->TerminateApp();
}

void on_key(vtkObject*, unsigned long, void* data, void*) {
  auto* c = static_cast<Callbacks*>(data);
  if (*c->key && c->interactor->GetKeySym()) (*c->key)(c->interactor->GetKeySym());
}

} // namespace

void ViewWindow::run(const std::function<bool()>& tick, double period, const std::function<void(const std::string&)>& key) {
  if (!m_interactor) throw std::logic_error("viewer: run() needs an on-screen window");
  m_interactor->Initialize();
  Callbacks callbacks{&tick, &key, m_interactor};
  auto timer = vtkSmartPointer<vtkCallbackCommand>::New();
  timer->SetCallback(on_timer);
  timer->SetClientData(&callbacks);
  m_interactor->AddObserver(vtkCommand::TimerEvent, timer);
  auto keys = vtkSmartPointer<vtkCallbackCommand>::New();
  keys->SetCallback(on_key);
  keys->SetClientData(&callbacks);
  m_interactor->AddObserver(vtkCommand::KeyPressEvent, keys);
  m_interactor->CreateRepeatingTimer(static_cast<unsigned long>(std::max(1.0, period * 1e3)));
  m_window->Render();
  m_interactor->Start();
  m_interactor->RemoveObserver(timer);
  m_interactor->RemoveObserver(keys);
}

} // namespace kerf
