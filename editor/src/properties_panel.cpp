#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMimeData>
#include <QPushButton>
#include <QScrollArea>
#include <QSpinBox>
#include <QTableWidget>
#include <QTimer>
#include <QToolButton>
#include <QVBoxLayout>
#include <cmath>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "canvas.hpp"
#include "panels.hpp"
#include "qt_text.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor::gui {

namespace {

// What the panel shows of one node, whatever its kind.
struct NodeView {
  const std::vector<app::Param>* params = nullptr;
  const std::vector<app::ParamSpec>* specs = nullptr;  ///< nullptr: unknown type or instance
  const app::ModuleType* moduleType = nullptr;
  std::string host;
  QString typeText;
  QString doc;
};

NodeView viewOf(const app::Application& app, const app::Catalog& catalog, const std::string& node) {
  NodeView view;
  if (const app::Module* module = app::findModule(app, node)) {
    view.params = &module->params;
    view.host = module->host;
    view.typeText = "module " + qtText(module->package + "/" + module->type);
    view.moduleType = catalog.findModule(module->package, module->type);
    if (view.moduleType != nullptr) {
      view.specs = &view.moduleType->params;
      view.doc = qtText(view.moduleType->doc);
    } else {
      view.doc = "Unknown module type: no installed package declares it.";
    }
  } else if (const app::Filter* filter = app::findFilter(app, node)) {
    view.params = &filter->params;
    view.host = filter->host;
    view.typeText = "filter " + qtText(filter->type);
    if (const auto* type = catalog.findFilter(filter->type)) {
      view.specs = &type->params;
      view.doc = qtText(type->doc);
    } else {
      view.doc = "Unknown filter type.";
    }
  } else if (const app::Instance* instance = app::findInstance(app, node)) {
    view.params = &instance->params;
    view.host = instance->host;
    view.typeText = "composite " + qtText(instance->composite);
  }
  return view;
}

// The parameters set on the node that its type does not declare, in file order.
std::vector<const app::Param*> undeclared(const NodeView& view) {
  std::vector<const app::Param*> found;
  for (const app::Param& p : *view.params) {
    const bool declared =
        view.specs != nullptr &&
        std::any_of(view.specs->begin(), view.specs->end(),
                    [&](const app::ParamSpec& spec) { return spec.name == p.name; });
    if (!declared) found.push_back(&p);
  }
  return found;
}

// Everything that decides which widgets the panel holds: when it is unchanged, the widgets stay
// and only their values change.
std::string structureOf(const app::Application& app, const NodeView& view,
                        const std::string& node) {
  std::string key = node + '\n' + stdText(view.typeText) + '\n';
  if (view.specs != nullptr) {
    for (const auto& spec : *view.specs) key += spec.name + ',';
  }
  key += '\n';
  for (const app::Param* p : undeclared(view)) key += p->name + ',';
  key += '\n';
  for (const auto& h : app.hosts) key += h.id + ',';
  return key;
}

// True when two texts hold the same numbers ("1e-3" and "0.001").
bool sameNumbers(const std::string& a, const std::string& b) {
  std::istringstream left(a), right(b);
  double x = 0, y = 0;
  bool same = true, any = false;
  while (left >> x) {
    if (!(right >> y) || x != y) same = false;
    any = true;
  }
  return any && same && !(right >> y);
}

}  // namespace

// ---- Properties --------------------------------------------------------------------------

PropertiesPanel::PropertiesPanel(QWidget* parent)
    : QWidget(parent), layout_(new QVBoxLayout(this)) {
  layout_->setContentsMargins(0, 0, 0, 0);
  clear();
}

// The old body goes later: show() runs from the signals of its own widgets (an edit is applied,
// the window refreshes), and a widget must not be deleted inside its own signal.
static void dropLater(QWidget*& body) {
  if (body == nullptr) return;
  body->hide();
  body->setParent(nullptr);
  body->deleteLater();
  body = nullptr;
}

void PropertiesPanel::clear() {
  dropLater(body_);
  body_ = new QWidget;
  auto* scroll = new QScrollArea;
  scroll->setWidgetResizable(true);
  scroll->setWidget(new QLabel("  Select a node to edit its properties."));
  auto* l = new QVBoxLayout(body_);
  l->setContentsMargins(0, 0, 0, 0);
  l->addWidget(scroll);
  layout_->addWidget(body_);
}

QWidget* PropertiesPanel::parameterWidget(const QString& name) const {
  return body_ == nullptr ? nullptr : body_->findChild<QWidget*>("param:" + name);
}

QWidget* PropertiesPanel::initialMessagesWidget(const QString& port) const {
  return body_ == nullptr ? nullptr : body_->findChild<QWidget*>("initial:" + port);
}

QWidget* PropertiesPanel::editorFor(const app::ParamSpec& spec, ParamRow& row) {
  const std::string node = node_;
  const std::string name = spec.name;
  const bool numeric = spec.type == app::ParamType::Int || spec.type == app::ParamType::Float ||
                       spec.type == app::ParamType::Vec3;
  // A widget left without a change (focus passing through) must not write the value it shows:
  // an unset parameter would become set to its default, "1e-3" would become "0.001".
  auto emitValue = [this, node, name, numeric](const std::string& v) {
    const auto it = rows_.find(name);
    if (it == rows_.end() || node != node_) return;
    const std::string& shown = it->second.shown;
    if (v == shown || (numeric && sameNumbers(v, shown))) return;
    Q_EMIT parameterEdited(node, name, v);
  };
  const std::string& shown = row.shown;
  QWidget* widget = nullptr;
  switch (spec.type) {
    case app::ParamType::Int: {
      auto* box = new QSpinBox;
      const double lo = spec.min.value_or(-1e9), hi = spec.max.value_or(1e9);
      box->setRange(static_cast<int>(std::max(lo, -2147483647.0)),
                    static_cast<int>(std::min(hi, 2147483647.0)));
      box->setKeyboardTracking(false);
      connect(box, &QSpinBox::editingFinished, this,
              [box, emitValue] { emitValue(std::to_string(box->value())); });
      row.display = [box](const std::string& v) {
        box->setValue(static_cast<int>(std::strtoll(v.c_str(), nullptr, 10)));
      };
      widget = box;
      break;
    }
    case app::ParamType::Float: {
      auto* box = new QDoubleSpinBox;
      box->setDecimals(6);
      box->setRange(spec.min.value_or(-1e12), spec.max.value_or(1e12));
      box->setKeyboardTracking(false);
      connect(box, &QDoubleSpinBox::editingFinished, this, [box, emitValue] {
        std::ostringstream text;
        text << std::setprecision(12) << box->value();
        emitValue(text.str());
      });
      row.display = [box](const std::string& v) { box->setValue(std::strtod(v.c_str(), nullptr)); };
      widget = box;
      break;
    }
    case app::ParamType::Bool: {
      auto* box = new QCheckBox;
      connect(box, &QCheckBox::toggled, this,
              [emitValue](bool on) { emitValue(on ? "true" : "false"); });
      row.display = [box](const std::string& v) { box->setChecked(v == "true" || v == "1"); };
      widget = box;
      break;
    }
    case app::ParamType::Enum: {
      auto* box = new QComboBox;
      for (const auto& choice : spec.choices) box->addItem(qtText(choice));
      connect(box, &QComboBox::activated, this,
              [box, emitValue] { emitValue(stdText(box->currentText())); });
      row.display = [box](const std::string& v) { box->setCurrentText(qtText(v)); };
      widget = box;
      break;
    }
    case app::ParamType::Vec3: {
      auto* fields = new QWidget;
      auto* h = new QHBoxLayout(fields);
      h->setContentsMargins(0, 0, 0, 0);
      h->setSpacing(2);
      std::vector<QDoubleSpinBox*> boxes;
      for (int i = 0; i < 3; ++i) {
        auto* box = new QDoubleSpinBox;
        box->setDecimals(4);
        box->setRange(spec.min.value_or(-1e9), spec.max.value_or(1e9));
        box->setKeyboardTracking(false);
        // Three numbers share the panel's width: no arrows (the wheel and keys still step).
        box->setButtonSymbols(QAbstractSpinBox::NoButtons);
        box->setObjectName(QString("component%1").arg(i));
        h->addWidget(box);
        boxes.push_back(box);
      }
      for (auto* box : boxes) {
        connect(box, &QDoubleSpinBox::editingFinished, this, [boxes, emitValue] {
          std::ostringstream text;
          text << std::setprecision(12) << boxes[0]->value() << ' ' << boxes[1]->value() << ' '
               << boxes[2]->value();
          emitValue(text.str());
        });
      }
      row.display = [boxes](const std::string& v) {
        std::istringstream in(v);
        for (QDoubleSpinBox* box : boxes) {
          double component = 0;
          in >> component;
          box->setValue(component);
        }
      };
      widget = fields;
      break;
    }
    case app::ParamType::File: {
      auto* fields = new QWidget;
      auto* h = new QHBoxLayout(fields);
      h->setContentsMargins(0, 0, 0, 0);
      auto* edit = new QLineEdit;
      edit->setObjectName("text");
      auto* browse = new QToolButton;
      browse->setText("\u2026");
      h->addWidget(edit);
      h->addWidget(browse);
      connect(edit, &QLineEdit::editingFinished, this,
              [edit, emitValue] { emitValue(stdText(edit->text())); });
      connect(browse, &QToolButton::clicked, this, [this, edit, emitValue] {
        const QString file =
            QFileDialog::getSaveFileName(this, "Choose a file", edit->text(), QString(), nullptr,
                                         QFileDialog::DontConfirmOverwrite);
        if (!file.isEmpty()) {
          edit->setText(file);
          emitValue(stdText(file));
        }
      });
      row.display = [edit](const std::string& v) { edit->setText(qtText(v)); };
      widget = fields;
      break;
    }
    case app::ParamType::String: {
      auto* edit = new QLineEdit;
      connect(edit, &QLineEdit::editingFinished, this,
              [edit, emitValue] { emitValue(stdText(edit->text())); });
      row.display = [edit](const std::string& v) { edit->setText(qtText(v)); };
      widget = edit;
      break;
    }
  }
  {
    // Signals blocked: showing a value is not an edit.
    const QSignalBlocker block(widget);
    std::vector<QSignalBlocker> blockers;
    for (QWidget* child : widget->findChildren<QWidget*>()) blockers.emplace_back(child);
    row.display(shown);
  }
  widget->setObjectName("param:" + qtText(name));
  // Spin boxes with wide ranges ask for much width: let them shrink to the panel.
  for (auto* box : widget->findChildren<QAbstractSpinBox*>())
    box->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
  if (auto* box = qobject_cast<QAbstractSpinBox*>(widget))
    box->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
  widget->setMinimumWidth(60);
  QString tip = qtText(spec.doc);
  tip += (tip.isEmpty() ? "" : "\n") + QString("type: ") + qtText(app::toString(spec.type));
  tip +=
      "\ndefault: " + (spec.defaultValue.empty() ? QString("(empty)") : qtText(spec.defaultValue));
  if (spec.min) tip += QString("\nmin: %1").arg(*spec.min);
  if (spec.max) tip += QString("\nmax: %1").arg(*spec.max);
  widget->setToolTip(tip);
  return widget;
}

// One parameter: label (context menu: override for this run), editor, reset and override
// buttons. A vec3 takes a row of its own under its label, so that its three fields fit.
void PropertiesPanel::addParameterRow(QFormLayout* form, const app::ParamSpec& spec, ParamRow& row,
                                      bool declared) {
  const std::string node = node_;
  const std::string name = spec.name;
  QWidget* editor = editorFor(spec, row);
  auto* line = new QWidget;
  auto* h = new QHBoxLayout(line);
  h->setContentsMargins(0, 0, 0, 0);
  h->addWidget(editor, 1);
  auto* overrideAction = new QAction("Override for this run\u2026", line);
  overrideAction->setToolTip("Use another value for the next run only (vrflow run --set " +
                             qtText(node + "." + name) + "=...); the file keeps its value");
  connect(overrideAction, &QAction::triggered, this, [this, node, name] {
    const auto it = rows_.find(name);
    if (it != rows_.end()) Q_EMIT overrideForRunRequested(node, name, it->second.shown);
  });
  auto* overrideButton = new QToolButton;
  overrideButton->setObjectName("override:" + qtText(name));
  overrideButton->setDefaultAction(overrideAction);
  overrideButton->setText("\u25b6");
  overrideButton->setAutoRaise(true);
  overrideButton->setFocusPolicy(Qt::NoFocus);  // Tab goes from field to field
  if (declared && spec.type != app::ParamType::Vec3) h->addWidget(overrideButton);
  row.label = new QLabel;
  row.label->setToolTip(editor->toolTip());
  row.label->setContextMenuPolicy(Qt::ActionsContextMenu);
  row.label->addAction(overrideAction);
  if (!declared) {
    h->addWidget(overrideButton);
    form->addRow(row.label, line);
    return;
  }
  row.reset = new QToolButton;
  row.reset->setText("\u21ba");
  row.reset->setFocusPolicy(Qt::NoFocus);
  row.reset->setToolTip("Reset to the default (" + qtText(spec.defaultValue) + ")");
  connect(row.reset, &QToolButton::clicked, this,
          [this, node, name] { Q_EMIT parameterEdited(node, name, ""); });
  h->addWidget(row.reset);
  if (spec.type == app::ParamType::Vec3) {
    auto* heading = new QWidget;
    auto* top = new QHBoxLayout(heading);
    top->setContentsMargins(0, 0, 0, 0);
    top->addWidget(row.label, 1);
    top->addWidget(overrideButton);
    form->addRow(heading);
    form->addRow(line);
  } else {
    form->addRow(row.label, line);
  }
}

void PropertiesPanel::show(const app::Application& app, const app::Catalog& catalog,
                           const std::string& node) {
  if (node.empty() || nodeKind(app, node) == NodeKind::None) {
    node_.clear();
    structure_.clear();
    rows_.clear();
    clear();
    return;
  }
  const std::string structure = structureOf(app, viewOf(app, catalog, node), node);
  if (node == node_ && structure == structure_ && body_ != nullptr) {
    updateInPlace(app, catalog);
    return;
  }
  node_ = node;
  structure_ = structure;
  build(app, catalog);
}

void PropertiesPanel::updateInPlace(const app::Application& app, const app::Catalog& catalog) {
  const NodeView view = viewOf(app, catalog, node_);
  auto update = [this](const std::string& name, const app::Param* p, const std::string& fallback) {
    ParamRow& row = rows_[name];
    const std::string shown = p == nullptr ? fallback : p->value;
    row.set = p != nullptr;
    QWidget* widget = parameterWidget(qtText(name));
    const QWidget* focus = QApplication::focusWidget();
    const bool typing = focus != nullptr && (focus == widget || widget->isAncestorOf(focus));
    // The field being typed in keeps its text (and cursor) unless its value changed.
    if (shown != row.shown || !typing) {
      row.shown = shown;
      const QSignalBlocker block(widget);
      std::vector<QSignalBlocker> blockers;
      for (QWidget* child : widget->findChildren<QWidget*>()) blockers.emplace_back(child);
      row.display(shown);
    }
    if (row.label != nullptr && row.reset != nullptr) {
      row.label->setText(qtText(name) + (row.set ? " \u2022" : ""));
      row.label->setStyleSheet(row.set ? "" : "color: #777;");
      row.reset->setEnabled(row.set);
    }
  };
  if (view.specs != nullptr) {
    for (const auto& spec : *view.specs) {
      update(spec.name, app::findParam(*view.params, spec.name), spec.defaultValue);
    }
  }
  for (const app::Param* p : undeclared(view)) update(p->name, p, p->value);
  if (auto* hosts = body_->findChild<QComboBox*>("host")) {
    const QSignalBlocker block(hosts);
    hosts->setCurrentText(qtText(app::effectiveHost(app, view.host)));
  }
  if (const app::Module* module = app::findModule(app, node_)) {
    for (auto* box : body_->findChildren<QSpinBox*>()) {
      if (!box->objectName().startsWith("initial:")) continue;
      const int count =
          app::inputConfigOrDefault(*module, stdText(box->objectName().mid(8))).initialMessages;
      if (box->value() == count) continue;
      const QSignalBlocker block(box);
      box->setValue(count);
    }
  }
}

void PropertiesPanel::build(const app::Application& app, const app::Catalog& catalog) {
  dropLater(body_);
  rows_.clear();
  const std::string node = node_;
  body_ = new QWidget;
  auto* outer = new QVBoxLayout(body_);
  outer->setContentsMargins(0, 0, 0, 0);
  auto* scroll = new QScrollArea;
  scroll->setWidgetResizable(true);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  auto* content = new QWidget;
  auto* form = new QFormLayout(content);
  form->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
  scroll->setWidget(content);
  outer->addWidget(scroll);
  layout_->addWidget(body_);

  const NodeView view = viewOf(app, catalog, node);
  auto* id = new QLineEdit(qtText(node));
  id->setObjectName("id");
  connect(id, &QLineEdit::editingFinished, this, [this, id, node] {
    if (stdText(id->text()) != node) Q_EMIT renameRequested(node, stdText(id->text()));
  });
  form->addRow("Id", id);
  auto* type = new QLabel("<b>" + view.typeText.toHtmlEscaped() + "</b>");
  form->addRow("Type", type);
  if (!view.doc.isEmpty()) {
    auto* docLabel = new QLabel(view.doc);
    docLabel->setWordWrap(true);
    docLabel->setStyleSheet("color: #555;");
    form->addRow(docLabel);
  }
  auto* hosts = new QComboBox;
  hosts->setObjectName("host");
  for (const auto& h : app.hosts) hosts->addItem(qtText(h.id));
  hosts->setCurrentText(qtText(app::effectiveHost(app, view.host)));
  connect(hosts, &QComboBox::activated, this,
          [this, hosts, node] { Q_EMIT hostChosen(node, stdText(hosts->currentText())); });
  form->addRow("Host", hosts);

  form->addRow(new QLabel("<b>Parameters</b>"));
  if (view.specs != nullptr) {
    for (const auto& spec : *view.specs) {
      const app::Param* p = app::findParam(*view.params, spec.name);
      ParamRow& row = rows_[spec.name];
      row.set = p != nullptr;
      row.shown = p == nullptr ? spec.defaultValue : p->value;
      addParameterRow(form, spec, row, true);
      row.label->setText(qtText(spec.name) + (row.set ? " \u2022" : ""));
      if (!row.set) row.label->setStyleSheet("color: #777;");
      row.reset->setEnabled(row.set);
    }
  }
  // Parameters the type does not declare (or of an instance): plain text.
  for (const app::Param* p : undeclared(view)) {
    app::ParamSpec spec;
    spec.name = p->name;
    spec.doc = view.specs == nullptr ? "" : "Not declared by the type: validation reports it.";
    ParamRow& row = rows_[p->name];
    row.set = true;
    row.shown = p->value;
    addParameterRow(form, spec, row, false);
    row.label->setText(qtText(p->name));
  }
  if (view.moduleType != nullptr) {
    const app::Module* module = app::findModule(app, node);
    form->addRow(new QLabel("<b>Inputs: initial messages</b>"));
    for (const auto& port : view.moduleType->ports) {
      if (!port.isInput) continue;
      auto* box = new QSpinBox;
      box->setObjectName("initial:" + qtText(port.name));
      box->setRange(0, 1000);
      box->setValue(app::inputConfigOrDefault(*module, port.name).initialMessages);
      box->setKeyboardTracking(false);
      box->setToolTip("Messages the input holds before the first iteration (what breaks a cycle)");
      const std::string portName = port.name;
      connect(box, &QSpinBox::editingFinished, this, [this, box, node, portName] {
        Q_EMIT initialMessagesEdited(node, portName, box->value());
      });
      form->addRow(qtText(port.name), box);
    }
  }
}

}  // namespace vrflow::editor::gui
