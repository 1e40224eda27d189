# Build-and-test image on Debian bookworm, with the same dependency script and
# build flags as .ci/run. The runtime stage (non-root, volume, HEALTHCHECK)
# arrives with the daemon and deployment issues.
FROM debian:bookworm AS build
WORKDIR /src
COPY deploy/install-deps.sh deploy/install-deps.sh
RUN bash deploy/install-deps.sh && rm -rf /var/lib/apt/lists/*
COPY . .
RUN cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DBOICP_WARNINGS_AS_ERRORS=ON \
 && cmake --build build -j"$(nproc)" \
 && ctest --test-dir build --output-on-failure -LE realdata

FROM debian:bookworm-slim AS runtime
COPY deploy/install-deps.sh /tmp/install-deps.sh
RUN bash /tmp/install-deps.sh && rm -rf /var/lib/apt/lists/* /tmp/install-deps.sh
COPY --from=build /src/build/bin/boicp /usr/local/bin/boicp
RUN useradd --system --create-home boicp
USER boicp
ENTRYPOINT ["boicp"]
