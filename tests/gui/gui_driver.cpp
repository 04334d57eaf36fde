// A user at MeshLab 2020.09's GUI, scripted: preloaded into Debian's `meshlab` (LD_PRELOAD), it
// waits for the main window, opens one filter's dialog from its menu action, types into fields
// found by their dialog labels (key events into the field's line edit, as a user types), presses
// Apply, answers any message box, takes screenshots of the window and exits. It knows nothing of
// the plugin: run_gui_e2e.py checks what the filter did with the typed values.
//
// Then, optionally, it switches on a render plugin's mode from Render > Shaders, moves MeshLab's
// light as a user does (Ctrl+Shift+drag in the view) and takes screenshots of the 3-D view.
//
// Environment (VBRDF_GUI_FILTER or VBRDF_GUI_RENDER needed, the rest optional):
//   VBRDF_GUI_FILTER  the menu entry (filter name) to open
//   VBRDF_GUI_RENDER  the render mode (Render > Shaders entry) to switch on after the filter ran
//                     (or at once without VBRDF_GUI_FILTER); screenshots (render_stage below) and
//                     copies of VBRDF_RELIGHT_VIEW_LOG beside them
//   VBRDF_GUI_LIGHT_DRAG  "dx,dy": then a Ctrl+Shift+drag by that many pixels from the view's
//                     centre, and view_moved.png, render_window_moved.png, view_moved.txt
//   VBRDF_GUI_TYPE    "label=text" entries separated by newlines: text typed into the field
//   VBRDF_GUI_SHOTS   folder for screenshots (window.png, dialog.png, after.png)
//   VBRDF_GUI_LOG     file the driver reports to (one "key: value" per line)
//   VBRDF_GUI_APPLY   0: only open the dialog, type and take screenshots (default 1)
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCoreApplication>
#include <QDir>
#include <QDockWidget>
#include <QFile>
#include <QGridLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QMainWindow>
#include <QMenu>
#include <QScreen>
#include <QMessageBox>
#include <QMouseEvent>
#include <QPushButton>
#include <QTextStream>
#include <QTimer>

namespace {

QString env(const char *name) { return QString::fromLocal8Bit(qgetenv(name)); }

void report(const QString &key, const QString &value) {
  const QString path = env("VBRDF_GUI_LOG");
  QString line = key + ": " + QString(value).replace('\n', ' ') + "\n";
  fputs(qUtf8Printable("gui_driver: " + line), stderr);
  if (path.isEmpty()) return;
  QFile f(path);
  if (f.open(QIODevice::Append | QIODevice::Text)) f.write(line.toUtf8());
}

void finish(int status) {
  report("exit", QString::number(status));
  fflush(nullptr);
  ::_exit(status);  // MeshLab's own shutdown may ask to save the project: not part of the test
}

// A screenshot of `w` as the X server shows it (QWidget::grab would leave MeshLab's OpenGL view black).
void shot(QWidget *w, const QString &name) {
  const QString dir = env("VBRDF_GUI_SHOTS");
  if (dir.isEmpty() || w == nullptr) return;
  QDir().mkpath(dir);
  const QString path = QDir(dir).filePath(name);
  QApplication::processEvents();
  const QPoint at = w->mapToGlobal(QPoint(0, 0));
  const QPixmap pixmap = QGuiApplication::primaryScreen()->grabWindow(0, at.x(), at.y(), w->width(), w->height());
  report("screenshot", pixmap.save(path) ? path : "FAILED " + path);
}

QMainWindow *main_window() {
  for (QWidget *w : QApplication::topLevelWidgets())
    if (auto *m = qobject_cast<QMainWindow *>(w))
      if (m->isVisible()) return m;
  return nullptr;
}

QDockWidget *filter_dialog(QMainWindow *window, const QString &filter) {
  for (QDockWidget *d : window->findChildren<QDockWidget *>())
    if (d->isVisible() && d->windowTitle() == filter) return d;
  return nullptr;
}

// Answers a message box (a failed filter's) and reports its text.
bool answer_message_boxes() {
  bool any = false;
  for (QWidget *w : QApplication::topLevelWidgets())
    if (auto *box = qobject_cast<QMessageBox *>(w))
      if (box->isVisible()) {
        report("message_box", box->windowTitle() + " | " + box->text());
        box->accept();
        any = true;
      }
  return any;
}

// The line edit of the field labelled `label`: MeshLab lays each field out as one row of a grid
// (label in column 0, editor or editor + "..." button in column 1), in the parameter frame.
QLineEdit *line_edit_in(QLayoutItem *item) {
  if (item == nullptr) return nullptr;
  if (auto *edit = qobject_cast<QLineEdit *>(item->widget())) return edit;
  if (item->widget() != nullptr) return item->widget()->findChild<QLineEdit *>();
  if (QLayout *layout = item->layout())
    for (int i = 0; i < layout->count(); ++i)
      if (QLineEdit *edit = line_edit_in(layout->itemAt(i))) return edit;
  return nullptr;
}

QLineEdit *field(QDockWidget *dialog, const QString &label) {
  for (QLabel *l : dialog->findChildren<QLabel *>()) {
    if (l->text() != label || l->parentWidget() == nullptr) continue;
    auto *grid = qobject_cast<QGridLayout *>(l->parentWidget()->layout());
    if (grid == nullptr) continue;
    const int index = grid->indexOf(l);
    if (index < 0) continue;
    int row = 0, column = 0, rows = 0, columns = 0;
    grid->getItemPosition(index, &row, &column, &rows, &columns);
    if (QLineEdit *edit = line_edit_in(grid->itemAtPosition(row, column + 1))) return edit;
  }
  return nullptr;
}

void type_into(QLineEdit *edit, const QString &text) {
  edit->setFocus();
  edit->selectAll();
  QKeyEvent del(QEvent::KeyPress, Qt::Key_Delete, Qt::NoModifier);
  QApplication::sendEvent(edit, &del);
  for (const QChar c : text) {
    QKeyEvent press(QEvent::KeyPress, 0, Qt::NoModifier, QString(c));
    QKeyEvent release(QEvent::KeyRelease, 0, Qt::NoModifier, QString(c));
    QApplication::sendEvent(edit, &press);
    QApplication::sendEvent(edit, &release);
  }
  QKeyEvent tab(QEvent::KeyPress, Qt::Key_Tab, Qt::NoModifier);  // leave the field, as a user would
  QApplication::sendEvent(edit, &tab);
}

// The lines of MeshLab's log panel that the Vertex BRDF filters wrote.
void report_log(QMainWindow *window) {
  for (QWidget *w : window->findChildren<QWidget *>()) {
    if (!w->inherits("QTextEdit") && !w->inherits("QPlainTextEdit")) continue;
    for (const QString &line : w->property("plainText").toString().split('\n'))
      if (line.contains("Vertex BRDF")) report("log", line.trimmed());
  }
}

// MeshLab's 3-D view (class GLArea, a QGLWidget) of the main window.
QWidget *gl_view(QMainWindow *window) {
  for (QWidget *w : window->findChildren<QWidget *>())
    if (w->inherits("GLArea") && w->isVisible()) return w;
  return nullptr;
}

// Copies the render plugin's view log (VBRDF_RELIGHT_VIEW_LOG) beside the screenshots as `name`.
void keep_view_log(const QString &name) {
  const QString log = env("VBRDF_RELIGHT_VIEW_LOG"), dir = env("VBRDF_GUI_SHOTS");
  if (log.isEmpty() || dir.isEmpty()) return;
  const QString to = QDir(dir).filePath(name);
  QFile::remove(to);
  report("view_log", QFile::copy(log, to) ? to : "MISSING " + log);
}

// A Ctrl+Shift+left-button drag from the view's centre (MeshLab's light trackball).
void drag_light(QWidget *view, int dx, int dy) {
  const Qt::KeyboardModifiers mods = Qt::ControlModifier | Qt::ShiftModifier;
  const QPoint from(view->width() / 2, view->height() / 2);
  QMouseEvent press(QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton, mods);
  QApplication::sendEvent(view, &press);
  const int steps = 10;
  for (int i = 1; i <= steps; ++i) {
    QMouseEvent move(QEvent::MouseMove, from + QPoint(dx * i / steps, dy * i / steps), Qt::NoButton, Qt::LeftButton, mods);
    QApplication::sendEvent(view, &move);
    QApplication::processEvents();
  }
  QMouseEvent release(QEvent::MouseButtonRelease, from + QPoint(dx, dy), Qt::LeftButton, Qt::NoButton, mods);
  QApplication::sendEvent(view, &release);
}

// Sets every visible check box labelled `text` (e.g. the render plugin's "Photo lights on a sphere").
void set_check_box(const QString &text, bool on) {
  for (QWidget *w : QApplication::allWidgets())
    if (auto *box = qobject_cast<QCheckBox *>(w))
      if (box->isVisible() && box->text() == text) box->setChecked(on);
}

// Switches on the render mode VBRDF_GUI_RENDER and takes screenshots: the window as it comes up
// (render_window.png); then, with the plugin's light sphere switched off so that only the model
// and MeshLab's own overlays are in the view, the view (view.png); after a light drag
// (VBRDF_GUI_LIGHT_DRAG) the view again (view_moved.png) and, with the sphere back on, the
// window (render_window_moved.png). Then exits.
void render_stage(QMainWindow *window) {
  const QString mode = env("VBRDF_GUI_RENDER");
  QAction *action = nullptr;
  for (QMenu *menu : window->findChildren<QMenu *>())
    for (QAction *a : menu->actions())
      if (a->text() == mode) action = a;
  if (action == nullptr) {
    report("error", "no render mode '" + mode + "' in the menus (render plugin not loaded?)");
    finish(2);
  }
  shot(gl_view(window), "view_before.png");  // MeshLab's own rendering of the same view
  action->trigger();
  report("render_mode", mode);
  const QString sphere = "Photo lights on a sphere";
  QTimer::singleShot(2500, window, [window, sphere] {
    report_log(window);
    QWidget *view = gl_view(window);
    if (view == nullptr) {
      report("error", "no 3-D view");
      finish(2);
    }
    report("view_size", QString::number(view->width()) + "x" + QString::number(view->height()));
    for (QWidget *w : QApplication::allWidgets())  // the render plugin's panel, in view coordinates
      if (w->objectName() == "VertexBrdfRelightPanel" && w->isVisible()) {
        const QPoint at = view->mapFromGlobal(w->mapToGlobal(QPoint(0, 0)));
        report("panel_rect", QString("%1,%2,%3,%4").arg(at.x()).arg(at.y()).arg(w->frameGeometry().width()).arg(w->frameGeometry().height()));
      }
    shot(window, "render_window.png");
    set_check_box(sphere, false);
    QTimer::singleShot(1500, window, [window, view, sphere] {
      shot(view, "view.png");
      keep_view_log("view.txt");
      const QStringList drag = env("VBRDF_GUI_LIGHT_DRAG").split(',');
      if (drag.size() != 2) finish(0);
      drag_light(view, drag[0].toInt(), drag[1].toInt());
      report("light_dragged", drag.join(","));
      QTimer::singleShot(2500, window, [window, view, sphere] {
        shot(view, "view_moved.png");
        keep_view_log("view_moved.txt");
        set_check_box(sphere, true);
        QTimer::singleShot(1500, window, [window] {
          shot(window, "render_window_moved.png");
          finish(0);
        });
      });
    });
  });
}

class Driver : public QObject {
public:
  Driver() {
    timer_.setInterval(300);
    connect(&timer_, &QTimer::timeout, this, [this] { step(); });
    timer_.start();
  }

private:
  enum class Stage { WaitWindow, WaitDialog, Applying, Done };

  void step() {
    ++ticks_;
    if (ticks_ > 2000) {  // 10 minutes
      report("error", "timed out in stage " + QString::number(int(stage_)));
      finish(3);
    }
    answer_message_boxes();
    QMainWindow *window = main_window();
    if (window == nullptr) return;
    const QString filter = env("VBRDF_GUI_FILTER");
    if (stage_ == Stage::WaitWindow) {
      if (settle_ == 0) {  // no window manager under Xvfb: showMaximized() does not fill the screen
        const QRect screen = QGuiApplication::primaryScreen()->geometry();
        window->setGeometry(0, 0, screen.width(), screen.height());
      }
      if (++settle_ < 10) return;  // let the project finish loading and drawing
      shot(window, "window.png");
      if (filter.isEmpty()) {  // render mode only
        stage_ = Stage::Done;
        render_stage(window);
        return;
      }
      // Filter actions belong to their plugins; the window holds them in its menus.
      QAction *action = nullptr;
      for (QMenu *menu : window->findChildren<QMenu *>())
        for (QAction *a : menu->actions())
          if (a->text() == filter) action = a;
      if (action == nullptr) {
        report("error", "no menu entry '" + filter + "' (plugin not loaded?)");
        finish(2);
      }
      report("menu_entry_enabled", action->isEnabled() ? "1" : "0");
      stage_ = Stage::WaitDialog;
      QTimer::singleShot(0, action, &QAction::trigger);
      return;
    }
    if (stage_ == Stage::WaitDialog) {
      QDockWidget *dialog = filter_dialog(window, filter);
      if (dialog == nullptr) return;
      report("dialog_size", QString::number(dialog->width()) + "x" + QString::number(dialog->height()));
      report("dialog_size_hint", QString::number(dialog->sizeHint().width()) + "x" +
                                     QString::number(dialog->sizeHint().height()));
      report("dialog_preview", dialog->findChildren<QWidget *>().isEmpty() ? "?" : has_preview(dialog) ? "1" : "0");
      for (const QString &entry : env("VBRDF_GUI_TYPE").split('\n', Qt::SkipEmptyParts)) {
        const int eq = entry.indexOf('=');
        const QString label = entry.left(eq), text = entry.mid(eq + 1);
        QLineEdit *edit = field(dialog, label);
        if (edit == nullptr) {
          report("error", "no text field labelled '" + label + "'");
          finish(2);
        }
        type_into(edit, text);
        report("typed", label + " = " + edit->text());
      }
      shot(dialog, "dialog.png");
      shot(window, "window_dialog.png");
      if (env("VBRDF_GUI_APPLY") == "0") finish(0);
      QPushButton *apply = nullptr;
      for (QPushButton *b : dialog->findChildren<QPushButton *>())
        if (b->text() == "Apply") apply = b;
      if (apply == nullptr) {
        report("error", "no Apply button");
        finish(2);
      }
      stage_ = Stage::Applying;
      // click() runs the filter inside this call (a failure opens a modal box, which step() answers).
      QTimer::singleShot(0, apply, [this, apply, window] {
        apply->click();
        report("applied", "1");
        report_log(window);
        QTimer::singleShot(1500, this, [window] {
          shot(window, "after.png");
          if (env("VBRDF_GUI_RENDER").isEmpty()) finish(0);
          for (QDockWidget *d : window->findChildren<QDockWidget *>())  // the filter's dialog covers the view
            if (d->isVisible() && d->windowTitle() == env("VBRDF_GUI_FILTER"))
              for (QPushButton *b : d->findChildren<QPushButton *>())
                if (b->text() == "Close") b->click();
          QTimer::singleShot(1000, window, [window] { render_stage(window); });
        });
      });
    }
  }

  static bool has_preview(QDockWidget *dialog) {
    for (QWidget *w : dialog->findChildren<QWidget *>())
      if (w->inherits("QCheckBox") && w->property("text").toString() == "Preview") return true;
    return false;
  }

  QTimer timer_;
  Stage stage_ = Stage::WaitWindow;
  int ticks_ = 0, settle_ = 0;
};

void start_driver() {
  if (env("VBRDF_GUI_FILTER").isEmpty() && env("VBRDF_GUI_RENDER").isEmpty()) return;
  // After the constructor of QApplication: the main window comes later, inside exec().
  QTimer::singleShot(0, [] { new Driver(); });
}

} // namespace

Q_COREAPP_STARTUP_FUNCTION(start_driver)
