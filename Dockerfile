# boicp image: boicpd (the gRPC map-building daemon) and boicp (the client).
#   docker build -t boicp:0.1.0 .
#   docker run -d --name boicpd -e BOICPD_WORKERS=2 -p 127.0.0.1:50051:50051 \
#     -v boicpd-data:/var/lib/boicpd boicp:0.1.0
# The build stage uses the same dependency script and configure flags as
# .ci/run but builds only the two binaries: .ci/run runs the tests on its host
# build, then runs this image with tests/deploy/test_image.sh. (podman keeps the
# HEALTHCHECK only with `podman build --format docker`.)
# The base stage holds only the runtime libraries, the user and the container
# settings; the last two stages add the two binaries to it.
# tests/deploy/check_deploy.py (ctest deploy_*) keeps this file in step with
# deploy/install-deps.sh, .ci/run and CMake.

FROM debian:bookworm AS build
WORKDIR /src
COPY deploy/install-deps.sh deploy/install-deps.sh
RUN bash deploy/install-deps.sh && rm -rf /var/lib/apt/lists/*
COPY . .
# .ci/run builds with -j2 on the 2-core CI machine; raise it on a bigger builder.
ARG BUILD_JOBS=2
RUN cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DBOICP_WARNINGS_AS_ERRORS=ON -DCMAKE_UNITY_BUILD=ON \
 && cmake --build build -j"${BUILD_JOBS}" --target boicpd boicp

FROM debian:bookworm-slim AS base
ARG VERSION=0.1.0
LABEL org.opencontainers.image.title="boicp" \
      org.opencontainers.image.description="BO-ICP map building: boicpd daemon, boicp client" \
      org.opencontainers.image.version="${VERSION}" \
      org.opencontainers.image.base.name="debian:bookworm-slim" \
      org.opencontainers.image.licenses="NOASSERTION"
COPY deploy/install-deps.sh /tmp/install-deps.sh
RUN bash /tmp/install-deps.sh --runtime && rm -rf /var/lib/apt/lists/* /tmp/install-deps.sh
# A fixed numeric uid so Kubernetes' runAsNonRoot can check it and volumes can be chowned to it.
RUN useradd --system --uid 10001 --user-group --home-dir /var/lib/boicpd \
      --shell /usr/sbin/nologin boicp \
 && mkdir -p /var/lib/boicpd \
 && chown boicp:boicp /var/lib/boicpd
# boicpd reads every flag from BOICPD_<FLAG> as well; the client reads BOICP_SERVER.
# On 0.0.0.0 boicpd is closed by default: it starts only with a token
# (BOICPD_AUTH_TOKEN_FILE, mounted) and TLS for it (BOICPD_TLS_CERT,
# BOICPD_TLS_KEY), or BOICPD_INSECURE=1 / BOICPD_INSECURE_NO_AUTH=1 set on purpose.
ENV BOICPD_LISTEN=0.0.0.0:50051 \
    BOICPD_DATA_DIR=/var/lib/boicpd \
    BOICP_SERVER=127.0.0.1:50051
VOLUME ["/var/lib/boicpd"]
EXPOSE 50051
USER 10001:10001
WORKDIR /var/lib/boicpd
# Health and reflection stay open without the bearer token, so the probe needs none.
HEALTHCHECK --interval=30s --timeout=5s --start-period=30s --retries=3 CMD ["boicp", "health"]
# boicpd blocks SIGTERM/SIGINT and waits for them, so as PID 1 it still drains on `docker stop`.
STOPSIGNAL SIGTERM
CMD ["boicpd"]

# The default target, `runtime`, takes the two binaries from the build stage.
# `--target prebuilt` takes build/bin/boicpd and build/bin/boicp of the build
# context instead and skips the build stage; they must come from a build on
# Debian bookworm with deploy/install-deps.sh (tests/deploy/test_image.sh
# --prebuilt gives it the binaries .ci/run has just built and tested). Both
# are stages of their own, not one chosen by a build argument, because
# podman's buildah skips a stage named only through an argument's default.
FROM base AS prebuilt
COPY build/bin/boicpd build/bin/boicp /usr/local/bin/

FROM base AS runtime
COPY --from=build /src/build/bin/boicpd /src/build/bin/boicp /usr/local/bin/
