# syntax=docker/dockerfile:1
# One image with both binaries (and the CLI). Build: docker build -t surfmap .
# Run:   docker run -p 8080:8080 -v surfmap-data:/data surfmap      (SQLite, in-process workers)
# Scale: deploy/docker-compose.yml (server, two workers, PostgreSQL).

FROM rust:1.95-bookworm AS build
WORKDIR /src
COPY . .
RUN cargo build --release --locked -p surfmap-server -p surfmap-worker -p surfmap-cli \
    && install -m 0755 target/release/surfmap-server target/release/surfmap-worker target/release/surfmap /usr/local/bin/

FROM debian:bookworm-slim
RUN useradd --system --uid 10001 --home-dir /data surfmap \
    && mkdir -p /data \
    && chown surfmap /data
COPY --from=build /usr/local/bin/surfmap-server /usr/local/bin/surfmap-worker /usr/local/bin/surfmap /usr/local/bin/
ENV SURFMAP_LISTEN=0.0.0.0:8080 \
    SURFMAP_DATA_DIR=/data \
    SURFMAP_DATABASE_URL=sqlite:///data/surfmap.db
VOLUME ["/data"]
EXPOSE 8080
USER 10001
WORKDIR /data
CMD ["surfmap-server"]
