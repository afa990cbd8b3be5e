#include "studio_server.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "elastic/core/error.h"
#include "job_file.h"
#include "studio_session.h"
// Last: httplib.h includes <resolv.h>, whose `_res` macro breaks Eigen's headers included after it.
#include <httplib.h>  // NOLINT(llvm-include-order)

namespace elastic::cli {
namespace {

// Request threads: the page keeps one event stream open and sends a few requests at a time;
// more connections queue (a bounded load test sends 100 at once).
constexpr size_t kRequestThreads = 16;
// Request bodies are JSON of a few KB (a job, a polygon of clicks).
constexpr size_t kMaxBody = 1 << 20;
// How long an event stream waits for a change before it sends a keep-alive comment.
constexpr double kStreamWaitSeconds = 10.0;

void send_json(httplib::Response& response, const nlohmann::json& body, int status = 200) {
  response.status = status;
  response.set_header("Cache-Control", "no-store");
  response.set_content(body.dump(), "application/json");
}

// The HTTP status of a failure: the page shows the message; the status tells a script why.
int status_of(const std::exception& error) {
  if (dynamic_cast<const UsageError*>(&error) != nullptr) {
    return 400;
  }
  if (dynamic_cast<const IoError*>(&error) != nullptr) {
    return 404;
  }
  if (dynamic_cast<const InvalidInputError*>(&error) != nullptr) {
    return 422;
  }
  if (dynamic_cast<const nlohmann::json::exception*>(&error) != nullptr) {
    return 400;
  }
  return 500;
}

// A JSON request body. \throws UsageError when it is not JSON.
nlohmann::json body_of(const httplib::Request& request) {
  try {
    return nlohmann::json::parse(request.body);
  } catch (const nlohmann::json::parse_error& e) {
    throw UsageError(std::string("request body is not JSON: ") + e.what());
  }
}

// Runs a handler, turning its exceptions into {"error": "elastic: ..."} with a status.
template <class F>
httplib::Server::Handler api(F&& handle) {
  return [handle = std::forward<F>(handle)](const httplib::Request& request,
                                            httplib::Response& response) {
    try {
      handle(request, response);
    } catch (const std::exception& e) {
      send_json(response, {{"error", StudioSession::error_line(e)}}, status_of(e));
    }
  };
}

std::string lower(std::string text) {
  for (char& c : text) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return text;
}

}  // namespace

void serve_studio(const StudioOptions& options,
                  const std::function<void(const std::string& url)>& listening) {
  if (!std::filesystem::is_regular_file(options.web_dir / "index.html")) {
    throw IoError(options.web_dir.string(),
                  "the studio's page is missing (index.html): build the elastic_cli target, "
                  "or give --web DIR");
  }
  StudioSession session({.roots = options.roots,
                         .work_dir = options.work_dir,
                         .frame_interval = options.frame_interval});
  // The answers of the last loads, for a page opened (or reloaded) later.
  std::mutex loaded_mutex;
  nlohmann::json loaded = nlohmann::json::object();
  const auto load = [&](Side side, const std::string& path) {
    nlohmann::json answer = session.load(side, path);
    std::lock_guard lock(loaded_mutex);
    loaded[answer["side"].get<std::string>()] = answer;
    return answer;
  };
  if (!options.source.empty()) {
    load(Side::Source, options.source);
  }
  if (!options.target.empty()) {
    load(Side::Target, options.target);
  }

  httplib::Server server;
  server.new_task_queue = [] { return new httplib::ThreadPool(kRequestThreads); };
  server.set_payload_max_length(kMaxBody);
  // One request per connection: an idle keep-alive connection holds a pool thread until it times
  // out, so a client that opens many (a browser, a load test) would starve the others. Loopback
  // connections cost microseconds; the event stream is one long response and unaffected.
  server.set_keep_alive_max_count(1);
  server.set_read_timeout(10);
  server.set_write_timeout(10);
  int port = 0;

  // Only requests to this server (a DNS name rebound to 127.0.0.1 is refused by Host) from its own
  // page (a cross-origin request carries another Origin).
  server.set_pre_routing_handler([&](const httplib::Request& request, httplib::Response& response) {
    const std::string host = lower(request.get_header_value("Host"));
    const std::string suffix = ":" + std::to_string(port);
    const bool host_ok = host == "127.0.0.1" + suffix || host == "localhost" + suffix;
    const std::string origin = lower(request.get_header_value("Origin"));
    const bool origin_ok = origin.empty() || origin == "http://127.0.0.1" + suffix ||
                           origin == "http://localhost" + suffix;
    if (host_ok && origin_ok) {
      // No compression: Debian's cpp-httplib compresses with brotli at its highest quality, which
      // takes seconds for a surface's few MB of JSON, and loopback needs none. The request object
      // is the server's own (not const), so dropping the header here is defined.
      const_cast<httplib::Request&>(request).headers.erase("Accept-Encoding");
      return httplib::Server::HandlerResponse::Unhandled;
    }
    send_json(response,
              {{"error", "elastic: studio: refused a request from another host or origin ('" +
                             (host_ok ? origin : host) + "')"}},
              403);
    return httplib::Server::HandlerResponse::Handled;
  });
  if (options.log) {
    server.set_logger(
        [&options](const httplib::Request& request, const httplib::Response& response) {
          if (response.status < 400) {
            return;
          }
          std::string line =
              request.method + " " + request.path + ": " + std::to_string(response.status);
          const nlohmann::json body = nlohmann::json::parse(response.body, nullptr, false);
          if (body.is_object() && body.contains("error") && body["error"].is_string()) {
            line += " " + body["error"].get<std::string>();
          }
          options.log(line);
        });
  }
  server.set_mount_point("/", options.web_dir.string());
  server.set_file_extension_and_mimetype_mapping("mjs", "text/javascript");

  server.Get("/api/state", api([&](const httplib::Request&, httplib::Response& response) {
               std::lock_guard lock(loaded_mutex);
               nlohmann::json sides = nlohmann::json::object();
               for (const auto& [side, answer] : loaded.items()) {
                 sides[side] = answer["path"];
               }
               send_json(response, {{"loaded", sides}, {"port", port}});
             }));
  server.Get("/api/surface", api([&](const httplib::Request& request, httplib::Response& response) {
               const std::string side = request.get_param_value("side");
               parse_side(side);
               std::lock_guard lock(loaded_mutex);
               if (!loaded.contains(side)) {
                 throw UsageError("no surface loaded on the " + side);
               }
               send_json(response, loaded[side]);
             }));
  server.Post("/api/load", api([&](const httplib::Request& request, httplib::Response& response) {
                const nlohmann::json body = body_of(request);
                send_json(response, load(parse_side(body.at("side").get<std::string>()),
                                         body.at("path").get<std::string>()));
              }));
  server.Post("/api/snap", api([&](const httplib::Request& request, httplib::Response& response) {
                const nlohmann::json body = body_of(request);
                const nlohmann::json& p = body.at("point");
                const Eigen::Vector3d x(p.at(0).get<double>(), p.at(1).get<double>(),
                                        p.at(2).get<double>());
                if (!x.allFinite()) {
                  throw UsageError("point: coordinates must be finite");
                }
                send_json(response,
                          session.snap(parse_side(body.at("side").get<std::string>()), x));
              }));
  server.Post("/api/region", api([&](const httplib::Request& request, httplib::Response& response) {
                const nlohmann::json body = body_of(request);
                send_json(response,
                          session.region(parse_side(body.at("side").get<std::string>()), body));
              }));
  server.Post("/api/map", api([&](const httplib::Request& request, httplib::Response& response) {
                send_json(response, session.start_map(body_of(request)));
              }));
  server.Post("/api/cancel", api([&](const httplib::Request&, httplib::Response& response) {
                session.cancel();
                send_json(response, {{"ok", true}});
              }));
  server.Post("/api/resolve",
              api([&](const httplib::Request& request, httplib::Response& response) {
                send_json(response, session.resolve(body_of(request)));
              }));
  server.Get("/api/result", api([&](const httplib::Request& request, httplib::Response& response) {
               const std::string baseline = request.has_param("baseline")
                                                ? request.get_param_value("baseline")
                                                : std::string("lscm");
               send_json(response, session.result(baseline));
             }));
  const auto download = [](httplib::Response& response, const nlohmann::json& body,
                           const std::string& name) {
    response.set_header("Content-Disposition", "attachment; filename=\"" + name + "\"");
    response.set_header("Cache-Control", "no-store");
    response.set_content(body.dump(2) + "\n", "application/json");
  };
  // The job file of the last finished run: for `elastic map --job` (?command=map, the default)
  // or `elastic paste --job` (?command=paste: the same keys, painting into the folder "out").
  server.Get("/api/job", api([&](const httplib::Request& request, httplib::Response& response) {
               nlohmann::json job = session.job();
               const std::string command = request.has_param("command")
                                               ? request.get_param_value("command")
                                               : std::string("map");
               if (command == "paste") {
                 job["command"] = "paste";
                 job["out"] = "elastic-paste";
               } else if (command != "map") {
                 throw UsageError("command: expected 'map' or 'paste', got '" + command + "'");
               }
               download(response, job, "elastic-" + command + "-job.json");
             }));
  server.Get("/api/report", api([&](const httplib::Request&, httplib::Response& response) {
               download(response, session.report(), "elastic-report.json");
             }));
  // Texture images of loaded meshes (and the source image), by path under the roots.
  server.Get("/api/file", api([&](const httplib::Request& request, httplib::Response& response) {
               const std::filesystem::path file =
                   session.allowed_path(request.get_param_value("path"));
               const std::string ext = lower(file.extension().string());
               const char* type = ext == ".png"                     ? "image/png"
                                  : ext == ".jpg" || ext == ".jpeg" ? "image/jpeg"
                                  : ext == ".bmp"                   ? "image/bmp"
                                                                    : nullptr;
               if (type == nullptr) {
                 throw UsageError("'" + file.string() + "' is not an image");
               }
               std::ifstream in(file, std::ios::binary);
               std::error_code size_error;
               const std::uintmax_t size = std::filesystem::file_size(file, size_error);
               std::string bytes(size_error ? 0 : size, '\0');
               if (!in || size_error ||
                   !in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) {
                 throw IoError(file.string(), "cannot be read");
               }
               response.set_content(bytes, type);
             }));
  // Long poll: the state once it changes after `version` (or after `wait` seconds).
  server.Get(
      "/api/events", api([&](const httplib::Request& request, httplib::Response& response) {
        const long version =
            request.has_param("version") ? std::stol(request.get_param_value("version")) : -1;
        const long frame =
            request.has_param("frame") ? std::stol(request.get_param_value("frame")) : 0;
        const double wait = request.has_param("wait")
                                ? std::clamp(std::stod(request.get_param_value("wait")), 0.0, 30.0)
                                : 0.0;
        send_json(response, session.events(version, frame, wait));
      }));
  // Server-sent events: every change of the run, frames included, until the client goes.
  server.Get("/api/stream", [&](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    response.set_chunked_content_provider(
        "text/event-stream",
        [&session, version = -1L, frame = 0L](size_t, httplib::DataSink& sink) mutable {
          if (!sink.is_writable()) {
            return false;
          }
          const nlohmann::json state = session.events(version, frame, kStreamWaitSeconds);
          if (state["version"].get<long>() == version) {
            const std::string ping = ": keep-alive\n\n";
            return sink.write(ping.data(), ping.size());
          }
          version = state["version"].get<long>();
          frame = state.value("frame_id", 0L);
          const std::string event = "data: " + state.dump() + "\n\n";
          return sink.write(event.data(), event.size());
        });
  });

  // Debian's compiled cpp-httplib listens with a backlog of 5: a burst of connections (a page
  // loading, a load test) overflows it, and the kernel then drops handshakes, which clients retry
  // for up to two minutes. The listening socket is caught here and listen() is called again with
  // the system's maximum, which Linux applies to a socket that is listening already.
  int listener = -1;
  server.set_socket_options([&listener](socket_t sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listener = sock;
  });
  port = options.port == 0 ? server.bind_to_any_port("127.0.0.1")
                           : (server.bind_to_port("127.0.0.1", options.port) ? options.port : -1);
  if (port <= 0) {
    throw IoError("127.0.0.1:" + std::to_string(options.port),
                  "cannot listen there (in use? give another --port, or --port 0 for any)");
  }
  if (listener >= 0) {
    ::listen(listener, SOMAXCONN);
  }
  listening("http://127.0.0.1:" + std::to_string(port) + "/");
  server.listen_after_bind();
}

}  // namespace elastic::cli
