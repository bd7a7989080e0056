# Servo Studio server image: Python backend plus the built browser UI.
FROM node:20-bookworm-slim AS frontend
WORKDIR /src/frontend
COPY frontend/package.json frontend/package-lock.json ./
RUN npm ci --no-audit --no-fund
COPY frontend/ ./
RUN npm run build

FROM python:3.11-slim-bookworm
WORKDIR /app
COPY pyproject.toml README.md ./
COPY backend/ backend/
COPY eds/ eds/
COPY motors/ motors/
COPY --from=frontend /src/backend/servostudio/static/ backend/servostudio/static/
RUN pip install --no-cache-dir -e .
COPY projects/ /app/projects/
EXPOSE 8000
# Inside the container the server must listen on all interfaces; docker-compose publishes it on localhost only.
# That needs users in the data directory ($SERVOSTUDIO_DATA_DIR): `servostudio user add NAME --level administrator`.
CMD ["servostudio", "serve", "--host", "0.0.0.0", "--allow-remote", "--port", "8000", "--projects", "/app/projects"]
