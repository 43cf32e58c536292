// Command check validates meshseek's Kubernetes manifests offline, without a
// cluster: every document is decoded strictly (unknown or mistyped fields are
// errors) into the Kubernetes API's own Go types (k8s.io/api), and every
// image, port, binary and flag the manifests name is checked against the
// built meshseek binaries.
//
//	go run ./deploy/k8s/check -bin build/services deploy/k8s/*.yaml
package main

import (
	"bytes"
	"flag"
	"fmt"
	"os"
	"os/exec"
	"path/filepath"
	"strings"

	appsv1 "k8s.io/api/apps/v1"
	autoscalingv2 "k8s.io/api/autoscaling/v2"
	corev1 "k8s.io/api/core/v1"
	"sigs.k8s.io/yaml"
)

var (
	binDir = flag.String("bin", "build/services", "folder of the built meshseek-* binaries")
	image  = flag.String("image", "meshseek:latest", "the image every container must run")
	cli    = flag.String("cli", "", "the meshseek command-line binary (default: <bin>/../cli/meshseek)")
)

type problems []string

func (p *problems) add(format string, args ...any) { *p = append(*p, fmt.Sprintf(format, args...)) }

// flagsOf returns the flags a binary accepts, from its --helpfull.
func flagsOf(binary string, cache map[string]string) (string, error) {
	if help, ok := cache[binary]; ok {
		return help, nil
	}
	path := filepath.Join(*binDir, binary)
	if binary == "meshseek" {
		path = *cli
		if path == "" {
			path = filepath.Join(*binDir, "..", "cli", "meshseek")
		}
	}
	out, _ := exec.Command(path, "--helpfull").CombinedOutput()
	if !bytes.Contains(out, []byte("Flags from")) {
		return "", fmt.Errorf("%s: no such binary in %s", binary, *binDir)
	}
	cache[binary] = string(out)
	return string(out), nil
}

func checkPod(where string, spec corev1.PodSpec, p *problems, help map[string]string) {
	for _, c := range spec.Containers {
		if c.Image != *image {
			p.add("%s: container %s runs image %q, want %q", where, c.Name, c.Image, *image)
		}
		if len(c.Args) == 0 {
			p.add("%s: container %s has no args (the role is the command)", where, c.Name)
			continue
		}
		flags, err := flagsOf(c.Args[0], help)
		if err != nil {
			p.add("%s: %v", where, err)
			continue
		}
		// The query page is the CLI's `web` command: an HTTP server, probed
		// over HTTP on its --port.
		args := c.Args[1:]
		web := c.Args[0] == "meshseek" && len(args) > 0 && args[0] == "web"
		if c.Args[0] == "meshseek" && !web {
			p.add("%s: container %s runs meshseek %v; only `meshseek web` is a server", where, c.Name, args)
			continue
		}
		if web {
			args = args[1:]
		}
		port, healthPort, metricsPort, tls, webTLS := "", "", "", false, false
		for _, a := range args {
			name, value, _ := strings.Cut(strings.TrimPrefix(a, "--"), "=")
			if !strings.Contains(flags, "-"+name+" ") && !strings.Contains(flags, "-"+name+")") {
				p.add("%s: %s has no flag --%s", where, c.Args[0], name)
			}
			switch name {
			case "port":
				port = value
			case "health_port":
				healthPort = value
			case "metrics_port":
				metricsPort = value
			case "tls_cert":
				tls = true
			case "web_tls_cert":
				webTLS = true
			}
		}
		ports := map[string]int32{}
		for _, cp := range c.Ports {
			ports[cp.Name] = cp.ContainerPort
			if listen := fmt.Sprint(cp.ContainerPort); listen != port && listen != healthPort && listen != metricsPort {
				p.add("%s: containerPort %d but the server listens on --port=%s (--health_port=%s, --metrics_port=%s)",
					where, cp.ContainerPort, port, healthPort, metricsPort)
			}
		}
		if web {
			for _, probe := range []*corev1.Probe{c.ReadinessProbe, c.LivenessProbe} {
				if probe == nil || probe.HTTPGet == nil {
					p.add("%s: container %s needs HTTP readiness and liveness probes", where, c.Name)
				} else if probe.HTTPGet.Port.String() != port {
					p.add("%s: probe on port %s, the page on %s", where, probe.HTTPGet.Port.String(), port)
				} else if webTLS != (probe.HTTPGet.Scheme == corev1.URISchemeHTTPS) {
					p.add("%s: probe scheme %q, but the page serves HTTPS: %v", where, probe.HTTPGet.Scheme, webTLS)
				}
			}
			if c.Resources.Requests.Cpu().IsZero() || c.Resources.Limits.Memory().IsZero() {
				p.add("%s: container %s needs resource requests and limits", where, c.Name)
			}
			continue
		}
		// kubelet's gRPC probes speak plaintext only: a TLS server is probed
		// on its plaintext health-only port.
		probePort := port
		if healthPort != "" {
			probePort = healthPort
		} else if tls {
			p.add("%s: container %s serves TLS but has no --health_port for kubelet's plaintext gRPC probes", where, c.Name)
		}
		for _, probe := range []*corev1.Probe{c.ReadinessProbe, c.LivenessProbe} {
			if probe == nil || probe.GRPC == nil {
				p.add("%s: container %s needs gRPC readiness and liveness probes", where, c.Name)
			} else if fmt.Sprint(probe.GRPC.Port) != probePort {
				p.add("%s: probe on port %d, server's health on %s", where, probe.GRPC.Port, probePort)
			}
		}
		if c.Resources.Requests.Cpu().IsZero() || c.Resources.Limits.Memory().IsZero() {
			p.add("%s: container %s needs resource requests and limits", where, c.Name)
		}
	}
	if spec.TerminationGracePeriodSeconds == nil || *spec.TerminationGracePeriodSeconds < 11 {
		p.add("%s: terminationGracePeriodSeconds must exceed the servers' 10 s drain", where)
	}
}

// checkMetrics: a server with --metrics_port is scraped by Prometheus'
// pod discovery, which finds it by the pod template's annotations.
func checkMetrics(where string, template corev1.PodTemplateSpec, p *problems) {
	for _, c := range template.Spec.Containers {
		for _, a := range c.Args {
			port, found := strings.CutPrefix(a, "--metrics_port=")
			if !found {
				continue
			}
			want := map[string]string{"prometheus.io/scrape": "true", "prometheus.io/port": port, "prometheus.io/path": "/metrics"}
			for key, value := range want {
				if template.Annotations[key] != value {
					p.add("%s: container %s serves metrics on %s: pod annotation %s must be %q", where, c.Name, port, key, value)
				}
			}
			named := false
			for _, cp := range c.Ports {
				named = named || (cp.Name == "metrics" && fmt.Sprint(cp.ContainerPort) == port)
			}
			if !named {
				p.add("%s: container %s needs containerPort %s named metrics", where, c.Name, port)
			}
		}
	}
}

func main() {
	flag.Parse()
	var p problems
	help := map[string]string{}
	for _, file := range flag.Args() {
		data, err := os.ReadFile(file)
		if err != nil {
			p.add("%v", err)
			continue
		}
		for i, doc := range bytes.Split(data, []byte("\n---\n")) {
			var meta struct{ Kind string }
			if err := yaml.Unmarshal(doc, &meta); err != nil {
				p.add("%s document %d: %v", file, i+1, err)
				continue
			}
			where := fmt.Sprintf("%s document %d (%s)", file, i+1, meta.Kind)
			var obj any
			switch meta.Kind {
			case "Namespace":
				obj = &corev1.Namespace{}
			case "Service":
				obj = &corev1.Service{}
			case "Deployment":
				obj = &appsv1.Deployment{}
			case "StatefulSet":
				obj = &appsv1.StatefulSet{}
			case "HorizontalPodAutoscaler":
				obj = &autoscalingv2.HorizontalPodAutoscaler{}
			case "Kustomization":
				continue
			default:
				p.add("%s: unexpected kind", where)
				continue
			}
			if err := yaml.UnmarshalStrict(doc, obj); err != nil {
				p.add("%s: %v", where, err)
				continue
			}
			switch o := obj.(type) {
			case *appsv1.Deployment:
				checkPod(where, o.Spec.Template.Spec, &p, help)
				checkMetrics(where, o.Spec.Template, &p)
			case *appsv1.StatefulSet:
				checkPod(where, o.Spec.Template.Spec, &p, help)
				checkMetrics(where, o.Spec.Template, &p)
				if len(o.Spec.VolumeClaimTemplates) == 0 {
					p.add("%s: a stateful role needs a volume claim", where)
				}
			case *corev1.Service:
				for _, sp := range o.Spec.Ports {
					if o.Labels["app.kubernetes.io/component"] == "web" {
						// The page serves HTTPS (its certificate, a token on every API call).
						if sp.TargetPort.String() != "https" || sp.Port != 8080 {
							p.add("%s: port %d -> %s, want 8080 -> https", where, sp.Port, sp.TargetPort.String())
						}
						continue
					}
					if sp.TargetPort.String() != "grpc" || sp.Port != 50051 {
						p.add("%s: port %d -> %s, want 50051 -> grpc", where, sp.Port, sp.TargetPort.String())
					}
				}
			}
			fmt.Printf("ok  %s\n", where)
		}
	}
	if len(p) > 0 {
		for _, msg := range p {
			fmt.Fprintln(os.Stderr, "FAIL", msg)
		}
		os.Exit(1)
	}
	fmt.Println("all manifests valid")
}
