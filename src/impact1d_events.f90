!> Event location on a step's dense output. Every watched function (a gap, a sliding
!> velocity) is a polynomial of degree <= 3 in the time theta since the step's start, so
!> its roots are isolated between the extrema and none is missed: two crossings inside one
!> step (a fast bounce, a graze) are found as surely as one.
module impact1d_events
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: hermite, earliest_crossing, poly_value, stop_force_cubic, first_negative

contains

  !> Cubic Hermite dense output of a displacement dx over [0, h] with end velocities v0, v1:
  !> dx(theta) = c(1) theta + c(2) theta^2 + c(3) theta^3. Exact when the motion is a cubic,
  !> as it is under piecewise-linear forcing. Built from the increment, not from positions,
  !> so a gap far from the origin keeps its digits.
  pure function hermite(dx, v0, v1, h) result(c)
    real(wp), intent(in) :: dx, v0, v1, h
    real(wp) :: c(3)
    c(1) = v0
    c(2) = (3.0_wp * dx / h - 2.0_wp * v0 - v1) / h
    c(3) = (v0 + v1 - 2.0_wp * dx / h) / h**2
  end function hermite

  !> A compliant stop's force F = -(k g + c g') (stiffness k, damping c) on a gap cubic
  !> g(theta) (docs/method.md section 10), a cubic too, and its tolerance: the gap's q
  !> carried through the same combination (both engines' stop location).
  pure subroutine stop_force_cubic(k, c, g, q, force, tol)
    real(wp), intent(in) :: k, c, g(0:3), q(0:3)
    real(wp), intent(out) :: force(0:3), tol(0:3)
    force = -[k * g(0) + c * g(1), k * g(1) + 2.0_wp * c * g(2), k * g(2) + 3.0_wp * c * g(3), k * g(3)]
    tol = k * q + c * [q(1), 2.0_wp * q(2), 3.0_wp * q(3), 0.0_wp]
  end subroutine stop_force_cubic

  pure real(wp) function poly_value(p, theta)
    real(wp), intent(in) :: p(0:3), theta
    poly_value = p(0) + theta * (p(1) + theta * (p(2) + theta * p(3)))
  end function poly_value

  !> Earliest theta in [0, h] where p turns negative: the zero at the start of the first
  !> piece of [0, h] (between consecutive roots) on which p falls below -tol(theta). Returns
  !> a value > h when there is none. tol keeps rounding-level wiggles of a resting function
  !> from counting, while the reported time is the true zero, not the -tol crossing; it is a
  !> polynomial in theta (coefficients >= 0) because rounding grows with what the step has
  !> moved by then: a crossing early in a long step is judged by the rounding there.
  pure real(wp) function earliest_crossing(p_given, h, tol) result(theta)
    real(wp), intent(in) :: p_given(0:3), h, tol(0:3)
    real(wp) :: p(0:3), nodes(5), crit(2)
    integer :: n_nodes, n_crit, j
    real(wp) :: a, b

    ! A -0 coefficient becomes +0: the stable root formula takes its sign (sign(.., qb) in
    ! stationary_points), so the roots found must not depend on which zero a sum of terms
    ! of absent bodies or contacts happened to give.
    p = p_given + 0.0_wp
    theta = 2.0_wp * h + 1.0_wp
    ! Cheap rejection, the common case: p cannot reach zero on [0, h].
    if (p(0) - h * (abs(p(1)) + h * (abs(p(2)) + h * abs(p(3)))) > 0.0_wp) return

    ! Monotone pieces between the extrema; a root is bracketed on each piece or absent.
    call stationary_points(p, h, crit, n_crit)
    n_nodes = 1
    nodes(1) = 0.0_wp
    a = 0.0_wp
    do j = 1, n_crit + 1
      if (j <= n_crit) then
        b = crit(j)
      else
        b = h
      end if
      if (poly_value(p, a) * poly_value(p, b) < 0.0_wp) then
        n_nodes = n_nodes + 1
        nodes(n_nodes) = bracketed_root(p, a, b)
      else if (poly_value(p, b) == 0.0_wp .and. b > 0.0_wp) then
        n_nodes = n_nodes + 1
        nodes(n_nodes) = b
      end if
      a = b
    end do
    if (nodes(n_nodes) < h) then
      n_nodes = n_nodes + 1
      nodes(n_nodes) = h
    end if
    do j = 1, n_nodes - 1
      a = nodes(j)
      b = nodes(j + 1)
      if (poly_value(p, 0.5_wp * (a + b)) < -poly_value(tol, 0.5_wp * (a + b)) .or. &
          poly_value(p, b) < -poly_value(tol, b)) then
        theta = a
        return
      end if
    end do
  end function earliest_crossing

  !> Zeros of p' strictly inside (0, h), ascending.
  pure subroutine stationary_points(p, h, crit, n)
    real(wp), intent(in) :: p(0:3), h
    real(wp), intent(out) :: crit(2)
    integer, intent(out) :: n
    real(wp) :: qa, qb, qc, disc, q, r(2)
    integer :: m, j
    qa = 3.0_wp * p(3)
    qb = 2.0_wp * p(2)
    qc = p(1)
    m = 0
    if (qa == 0.0_wp) then
      if (qb /= 0.0_wp) then
        m = 1
        r(1) = -qc / qb
      end if
    else
      disc = qb**2 - 4.0_wp * qa * qc
      if (disc >= 0.0_wp) then
        ! Stable form: no cancellation between qb and the square root.
        q = -0.5_wp * (qb + sign(sqrt(disc), qb))
        if (q /= 0.0_wp) then
          m = 2
          r(1) = q / qa
          r(2) = qc / q
        else
          m = 1
          r(1) = 0.0_wp
        end if
      end if
    end if
    n = 0
    do j = 1, m
      if (r(j) > 0.0_wp .and. r(j) < h) then
        n = n + 1
        crit(n) = r(j)
      end if
    end do
    if (n == 2) then
      if (crit(1) > crit(2)) crit = crit([2, 1])
    end if
  end subroutine stationary_points

  !> The root of p in (a, b), where p(a) and p(b) differ in sign, to the last bit: the bracket
  !> shrinks until its ends are adjacent numbers. Newton's point is taken when it falls inside
  !> the bracket, the midpoint otherwise, so the root is never left (a monotone piece has
  !> exactly one); once Newton's step is below the numbers' spacing, a point just across the
  !> root closes the bracket. A handful of evaluations instead of bisection's fifty.
  pure real(wp) function bracketed_root(p, a0, b0) result(root)
    real(wp), intent(in) :: p(0:3), a0, b0
    real(wp) :: a, b, fa, x, fx, slope, step
    integer :: iteration
    a = a0
    b = b0
    fa = poly_value(p, a)
    x = 0.5_wp * (a + b)
    do iteration = 1, 200
      if (.not. (x > a .and. x < b)) x = 0.5_wp * (a + b)
      if (.not. (x > a .and. x < b)) exit      ! a and b are adjacent numbers
      fx = poly_value(p, x)
      if (fx == 0.0_wp) then
        a = x
        b = x
        exit
      end if
      if ((fx < 0.0_wp) .eqv. (fa < 0.0_wp)) then
        a = x
        fa = fx
      else
        b = x
      end if
      slope = p(1) + x * (2.0_wp * p(2) + 3.0_wp * x * p(3))
      if (slope == 0.0_wp) then
        x = 0.5_wp * (a + b)
        cycle
      end if
      step = fx / slope
      if (abs(step) <= spacing(x)) step = sign(2.0_wp * spacing(x), step)
      x = x - step
    end do
    ! The earlier end: a crossing is never reported after the function went negative.
    root = a
    if (poly_value(p, b) >= 0.0_wp .and. fa < 0.0_wp) root = b
  end function bracketed_root

  !> First tau > 0 with g0 + u tau + a tau^2 / 2 < 0, for g0 >= 0 (0 if g0 < 0, huge if never):
  !> when a gap or a sliding velocity under constant forces can first need watching (the
  !> closed-form steps' quiet time, impact1d_nbody_glide).
  pure real(wp) function first_negative(g0, u, a) result(tau)
    real(wp), intent(in) :: g0, u, a
    real(wp) :: disc, q
    tau = huge(1.0_wp)
    if (g0 < 0.0_wp) then
      tau = 0.0_wp
    else if (a == 0.0_wp) then
      if (u < 0.0_wp) tau = g0 / (-u)
    else
      disc = u**2 - 2.0_wp * a * g0
      if (disc < 0.0_wp) return
      ! Roots of a/2 tau^2 + u tau + g0 by the stable pair q/(a/2) and g0/q.
      q = -0.5_wp * (u + sign(sqrt(disc), u))
      if (a > 0.0_wp) then
        if (u < 0.0_wp .and. q /= 0.0_wp) tau = g0 / q        ! the smaller positive root
      else
        tau = max(q / (0.5_wp * a), merge(g0 / q, 0.0_wp, q /= 0.0_wp))   ! the positive root
      end if
      tau = max(tau, 0.0_wp)
    end if
    if (tau /= tau) tau = 0.0_wp
  end function first_negative
end module impact1d_events
