#!/usr/bin/python3
"""meshseek from Python: make a collection of a folder of meshes, build it, query it.

    build/cli/meshseek synth --out out/synthetic        # a labelled synthetic benchmark
    build/cli/meshseek serve --port 50051 &              # the whole stack in one process
    PYTHONPATH=build/python python3 python/example.py --server localhost:50051 \
        --folder out/synthetic --param points=256 --param vocabulary=64

Labels come from FOLDER/manifest.csv (id,class,path) when there is one. The
query is the first model of the folder unless --query names a mesh file. A
collection with lfd (--method dld+lfd, or the default fusion) is also queried
by a picture: --picture FILE (PNG or JPEG), or the query model's own thumbnail.
"""

import argparse
import os
import sys

import grpc

import meshseek_client


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="localhost:50051", help="coordinator host:port")
    parser.add_argument("--folder", default="out/synthetic", help="meshes (and manifest.csv)")
    parser.add_argument("--collection", default="python-example")
    parser.add_argument("--method", default="dld")
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a pipeline parameter (meshseek --help lists them); repeatable")
    parser.add_argument("--query", help="mesh file to query with (default: the folder's first)")
    parser.add_argument("--picture", help="PNG or JPEG to query with as well (needs lfd)")
    parser.add_argument("--top_k", type=int, default=5)
    parser.add_argument("--tls_ca", help="CA bundle (PEM) to verify the server with")
    parser.add_argument("--token_file", help="file holding the bearer token (needs --tls_ca)")
    args = parser.parse_args()

    if any("=" not in p for p in args.param):
        parser.error("--param takes NAME=VALUE")
    params = dict(p.split("=", 1) for p in args.param)
    token = open(args.token_file).read().strip() if args.token_file else None
    models = meshseek_client.models_in_folder(args.folder)
    if not models:
        sys.exit(f"example: no meshes in {args.folder}")

    with meshseek_client.connect(args.server, token=token, tls_ca=args.tls_ca) as client:
        collection = client.create_collection(args.collection, method=args.method, **params)
        stored = {v.name: v.value for v in collection.params.values}
        shown = ["method"] + [k for k in params if k in stored]
        print(f"collection {collection.name}: " + " ".join(f"{k}={stored.get(k)}" for k in shown) +
              f" (and {len(stored) - len(shown)} more parameters at their defaults)")

        job = client.ingest(args.collection, models)
        done = client.wait(job)
        print(f"ingest: {len(models)} models streamed; {done.job_id}: {done.message}")

        built = client.wait(client.build(args.collection).job_id)
        print(f"build: {built.message}")

        query = args.query or models[0][1]
        known = {os.path.abspath(path): (model_id, label) for model_id, path, label in models}
        model_id, label = known.get(os.path.abspath(query), ("-", "-"))
        response = client.query(args.collection, query, top_k=args.top_k)
        print(f"query {query} (model {model_id}, class {label}): "
              f"{response.query_features} features; nearest:")
        print_ranking(response)

        if args.picture or "lfd" in args.method.split("+"):
            picture = args.picture
            if not picture:  # the query model's thumbnail, as a picture of it
                picture = os.path.join(args.folder, f"thumbnail-{model_id}.png")
                with open(picture, "wb") as f:
                    f.write(client.thumbnail(args.collection, model_id))
            response = client.query_by_image(args.collection, picture, top_k=args.top_k)
            print(f"picture {picture}: nearest:")
            print_ranking(response)


def print_ranking(response):
    print(f"{'rank':>4}  {'model':<12} {'label':<12} distance")
    for rank, r in enumerate(response.results, 1):
        print(f"{rank:>4}  {r.model_id:<12} {r.label:<12} {r.distance:.6g}")


if __name__ == "__main__":
    try:
        main()
    except grpc.RpcError as e:  # the server's status, e.g. INVALID_ARGUMENT naming a bad model
        sys.exit(f"example: {e.code().name}: {e.details()}")
    except (RuntimeError, OSError) as e:  # a failed job, no server, an unreadable file
        sys.exit(f"example: {e}")
