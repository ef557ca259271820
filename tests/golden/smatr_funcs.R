# smatr functions copied from traitecoevo/smatr (R/line.cis.R @1b65f3b, R/slope.test.R,
# R/elev.test.R, R/slope.com.R, R/lr.b.com.R, R/com.ci.R, R/elev.com.R @37ab116,
# R/b.com.est.R @a9688bb), non-robust branches only, 'data=' attach removed.
line.cis <- function( y, x, alpha=0.05, method="SMA", f.crit=0)
{
    dat  <- data.frame( y, x )
    datm <- as.matrix(na.omit(dat))
    n <- nrow(datm)
    res.df <- n-2
    if (f.crit == 0)f.crit <- qf( 1 - alpha, 1, res.df )
    r.factor1 <- 1
    r.factor2 <- 1
    vr <- ( var(datm) )*(n-1)
    means    <- apply(datm,2,mean)
    r   <- vr[1,2] / sqrt( vr[1,1]*vr[2,2] )
    cis <- matrix( 0, 2, 2)
    if ( method == 0 | method=="OLS" )
    {
        b        <- vr[1,2] / vr[2,2]
        var.res  <- ( vr[1,1] - 2*b*vr[1,2] + b^2*vr[2,2] ) / res.df
        var.b    <- var.res / vr[2,2] * r.factor1
        cis[2,1] <- b - sqrt(var.b)*sqrt(f.crit)
        cis[2,2] <- b + sqrt(var.b)*sqrt(f.crit)
    }
    if ( method==1 | method=="SMA" )
    {
        b        <- sign( vr[1,2] ) * sqrt( vr[1,1] / vr[2,2] )
        bigb     <- f.crit * ( 1 - r^2 ) / res.df * r.factor1
        cis[2,1] <- b*( sqrt(bigb+1) - sqrt(bigb) )
        cis[2,2] <- b*( sqrt(bigb+1) + sqrt(bigb) )
        if(b<0) cis[2,] = cis[2,c(2,1)]
        var.res  <- ( vr[1,1] - 2*b*vr[1,2] + b^2*vr[2,2] ) / res.df
        var.b    <- ( vr[1,1] - vr[1,2]^2/vr[2,2] ) / res.df/vr[2,2] * r.factor1
    }
    if ( method==2 | method=="MA" )
    {
        fac      <- vr[1,1] - vr[2,2]
        b        <- ( fac + sqrt( fac^2 + 4*vr[1,2]^2 ) ) / 2 / vr[1,2]
        Q        <- f.crit*( vr[1,1]*vr[2,2] - vr[1,2]^2 ) / res.df * r.factor1
        if ( (fac^2 + 4*vr[1,2]^2 - 4*Q ) < 0 ) { cis[2,1] <- -Inf; cis[2,2] <- Inf }
        else {
            cis[2,1] <- (fac + sqrt( fac^2 + 4*vr[1,2]^2 - 4*Q ) ) / 2 / ( vr[1,2] + sqrt(Q) )
            cis[2,2] <- (fac + sqrt( fac^2 + 4*vr[1,2]^2 - 4*Q ) ) / 2 / ( vr[1,2] - sqrt(Q) )
        }
        var.res  <- ( vr[1,1] - 2*b*vr[1,2] + b^2*vr[2,2] ) / res.df
        var.fit  <- ( b^2*vr[1,1] + 2*b*vr[1,2] + vr[2,2] ) / res.df
        var.b    <- 1 / ( var.res/var.fit + var.fit/var.res - 2 )*( 1 + b^2 )^2 / res.df * r.factor1
    }
    a        <- means[1] - b*means[2]
    var.a  <- var.res/n*r.factor2 + var.b*means[2]^2
    cis[1,1] <- a - sqrt(var.a)*sqrt(f.crit)
    cis[1,2] <- a + sqrt(var.a)*sqrt(f.crit)
    list(a=a, b=b, a.ci=cis[1,], b.ci=cis[2,], var.b=var.b, var.a=var.a)
}

slope.test <- function( y, x, test.value=1, method="SMA", alpha=0.05 )
{
    iref <- ( is.na(x+y) == FALSE )
    n    <- sum(iref)
    resDF <- n - 2
    dat <- cbind(y[iref], x[iref])
    r.factor <- 1
    vr <- ( cov(dat) )*(n-1)
    varTest <- matrix( 0, 2, 2 )
    if ( (method==0) | (method=='OLS') ) {
        b            <- vr[1,2]/vr[2,2]
        varTest[1,1] <- vr[1,1] - 2*test.value*vr[1,2] + test.value^2*vr[2,2]
        varTest[1,2] <- vr[1,2] - test.value*vr[2,2]
        varTest[2,2] <- vr[2,2]
    } else if ( (method==1) | (method=='SMA') ) {
        b            <- sign(vr[1,2])*sqrt(vr[1,1]/vr[2,2])
        varTest[1,1] <- vr[1,1] - 2*test.value*vr[1,2] + test.value^2*vr[2,2]
        varTest[1,2] <- vr[1,1] - test.value^2*vr[2,2]
        varTest[2,2] <- vr[1,1] + 2*test.value*vr[1,2] + test.value^2*vr[2,2]
    } else if ( (method==2) | (method=='MA') ) {
        fac          <- vr[1,1] - vr[2,2]
        b            <- ( fac + sqrt( fac^2 + 4*vr[1,2]^2) )/2/vr[1,2]
        varTest[1,1] <- vr[1,1] - 2*test.value*vr[1,2] + test.value^2*vr[2,2]
        varTest[1,2] <- -test.value^2*vr[1,2] + test.value*( vr[1,1] - vr[2,2] ) + vr[1,2]
        varTest[2,2] <- test.value^2*vr[1,1] + 2*test.value*vr[1,2] + vr[2,2]
    }
    rTest  <- varTest[1,2] / sqrt( varTest[1,1] ) / sqrt( varTest[2,2] )
    F      <- rTest^2/(1 - rTest^2)/r.factor*(n-2)
    pValue <- 1 - pf( F, 1, resDF)
    list( F=F, r=rTest, p=pValue, test.value=test.value, b=b )
}

elev.test <- function( y, x, test.value=0, alpha=0.05, method="SMA" )
{
    iref <- ( is.na(x+y) == FALSE )
    n    <- sum(iref)
    res.df <- n - 2
    fcrit  <- qf( 1-alpha, 1, res.df )
    dat    <- cbind( y[iref], x[iref] )
    r.factor1 <- 1; r.factor2 <- 1
    means    <- apply(dat,2,mean)
    vr <- ( var(dat) )*(n-1)
    if ( (method==0) | (method=="OLS") ) {
        b       <- vr[1,2] / vr[2,2]
        var.res <- ( vr[1,1] - 2*b*vr[1,2] + b^2*vr[2,2] ) / res.df
        var.b   <- var.res / vr[2,2]
    } else if ( (method==1) | (method=="SMA") ) {
        b       <- sign( vr[1,2] )*sqrt( vr[1,1] / vr[2,2] )
        var.res <- ( vr[1,1] - 2*b*vr[1,2] + b^2*vr[2,2] ) / res.df
        var.b   <- ( vr[1,1] - (vr[1,2]^2)/vr[2,2] ) / res.df / vr[2,2]
    } else if ( (method==2) | (method=="MA") ) {
        fac     <- vr[1,1] - vr[2,2]
        b       <- ( fac + sqrt( fac^2 + 4*vr[1,2]^2) ) / 2 / vr[1,2]
        var.res <- ( vr[1,1] - 2*b*vr[1,2] + b^2*vr[2,2] ) / res.df
        var.fit <- ( b^2*vr[1,1] + 2*b*vr[1,2] + vr[2,2] ) / res.df
        var.b   <- 1 / ( var.res/var.fit + var.fit/var.res - 2)*( 1 + b^2 )^2 / res.df
    }
    a        <- means[1] - b*means[2]
    var.a    <- var.res/n*r.factor2 + var.b*means[2]^2*r.factor1
    t        <- (a - test.value)/sqrt(var.a)
    pvalue   <- 2*pt( -abs(t), res.df )
    list( t=t, a=a, p=pvalue, a.ci=c( a-sqrt(var.a*fcrit), a+sqrt(var.a*fcrit) ), test.value=test.value )
}

b.com.est <- function( z, n, method, lambda=1, res.df)
{
    zcom    <- t(z) %*% ( n - 1 )
    iter    <- 100
    bi      <- matrix( 0, iter, 1 )
    bchange <- 1
    i       <- 1
    while ( abs(bchange) > 10^(-6) )
    {
        i  <- i+1;
        if ( i > 100 ) { warning("no convergence!"); i <- i-1; break }
        if ( (method==1) | (method=="SMA") ) {
            bi[i] <- sign( zcom[3] )*sqrt( zcom[1]/zcom[2] )
            l1    <- ( bi[i]^2*z[,2] + 2*bi[i]*z[,3] + z[,1] )/2/abs(bi[i])
            l2    <- ( bi[i]^2*z[,2] - 2*bi[i]*z[,3] + z[,1] )/2/abs(bi[i])
            wts   <- n * (1/l2 + 1/l1)
            wts[n==1] <- 0
            zcom  <- t(z) %*% wts
        } else if ( (method==2) | (method=="MA") ) {
            fac   <- zcom[1] - lambda*zcom[2]
            bi[i] <- ( fac + sqrt( fac^2 + 4*lambda*zcom[3]^2 ) ) /2/zcom[3]
            l1    <- ( lambda^2*z[,2] + 2*lambda*bi[i]*z[,3] + bi[i]^2*z[,1] ) / (lambda+bi[i]^2)
            l2    <- ( bi[i]^2*z[,2] - 2*bi[i]*z[,3] + z[,1] )/ ( lambda + bi[i]^2 )
            wts   <- n * (1/l2 - lambda/l1)
            wts[n==1] <- 0
            zcom  <- t(z) %*% wts
        }
        bchange <- bi[i] - bi[i-1]
        b       <- bi[i]
    }
    if ( (method==1) | (method=='SMA') ) { lambda <- b^2 }
    list( b=b, bi=bi[2:i], l1=l1, l2=l2, lambda=lambda )
}

lr.b.com <- function( b, arguments )
{
    l1 <- arguments$l1; l2 <- arguments$l2; z <- arguments$z; n <- arguments$n
    method <- arguments$method; crit <- arguments$crit; lambda <- arguments$lambda
    res.df <- arguments$res.df; r.factor <- arguments$r.factor
    if ( (method==1) | (method=='SMA') ) {
        if ( b==0 ) b <- 10^-6
        l1b <- ( b^2*z[,2] + 2*b*z[,3] + z[,1] )/2/abs(b)
        l2b <- ( b^2*z[,2] - 2*b*z[,3] + z[,1] )/2/abs(b)
    } else {
        l1b <- ( lambda^2*z[,2] + 2*lambda*b*z[,3] + b^2*z[,1] )/( lambda + b^2 )
        l2b <- ( b^2*z[,2] - 2*b*z[,3] + z[,1] )/( lambda + b^2 )
    }
    sum( ( res.df - 0.5 ) * log (1 + ( l1b*l2b/l1/l2 - 1 ) / r.factor ), na.rm=TRUE ) - crit
}

com.ci <- function( b, varb, crit, z, n, l1, l2, method, lambda, res.df, r.factor, tol=0.0001)
{
    b.ci <- c(NA,NA)
    arguments <- list( l1=l1, l2=l2, z=z, n=n, method=method, crit=crit, lambda=lambda, res.df=res.df, r.factor=r.factor )
    val.b <- lr.b.com(b,arguments)
    b.m   <- b - 2*sqrt(crit*varb)
    b.p   <- b + 2*sqrt(crit*varb)
    val.m <- lr.b.com(b.m,arguments)
    val.p <- lr.b.com(b.p,arguments)
    if ( val.m*val.b > 0 ) { b.m <- b - 4*sqrt(crit*varb); val.m <- lr.b.com(b.m,arguments) }
    if ( val.p*val.b > 0 ) { b.p <- b + 4*sqrt(crit*varb); val.p <- lr.b.com(b.p,arguments) }
    if ( val.m*val.b > 0 ) { b.m <- b - 8*sqrt(crit*(varb+0.1)); val.m <- lr.b.com(b.m,arguments) }
    if ( val.p*val.b > 0 ) { b.p <- b + 8*sqrt(crit*(varb+0.1)); val.p <- lr.b.com(b.p,arguments) }
    res <- uniroot( lr.b.com, c(b.m, b ), tol = tol, arguments=arguments )
    b.ci[1] <- res$root
    res <- uniroot( lr.b.com, c(b , b.p ), tol = tol, arguments=arguments )
    b.ci[2] <- res$root
    b.ci
}

slope.com <- function( y, x, groups, method="SMA", alpha=0.05, group.names=sort(unique(groups)), ci=TRUE, tol=0.0001 )
{
    dat    <- cbind(y, x)
    g      <- length(group.names)
    n      <- matrix( 0, g, 1 )
    r.factor      <- matrix( 0, g, 1 )
    z      <- matrix( 0, g, 3 )
    for (i in 1:g) {
        iref   <- ( groups==group.names[i] )
        iref   <- iref & ( is.na(x+y) == FALSE )
        n[i]   <- sum(iref)
        r.factor[i]<-1
        xi <- cov(dat[iref, ])
        z[i,]     <- c( xi[1,1], xi[2,2], xi[1,2] )
    }
    res.df <- n-2
    lambda <- 1
    res    <- b.com.est( z, n, method, lambda, res.df=res.df )
    dets <- z[,1]*z[,2] - z[,3]^2
    arguments <- list( l1=dets, l2=1, z=z, n=n, method=method, crit=0, lambda=lambda, res.df=res.df, r.factor=r.factor)
    LR     <- lr.b.com(res$b, arguments)
    b      <- res$b; l1 <- res$l1; l2 <- res$l2; lambda <- res$lambda
    df <- g - 1 - sum(n<=1)
    Pvalue <- 1 - pchisq( LR, df )
    if ( (method==1) | (method=='SMA') ) {
       varBs <- ( l2/l1 + l1/l2 + 2)^(-1) *  ( 4*b^2 ) * r.factor
       l12   <- ( l1 + l2 )^2 / ( l1*l2 )
    } else {
       varBs <- ( l2/l1 + l1/l2 - 2)^(-1) * ( lambda + b^2 )^2 * r.factor
       l12 <- ( l1 - l2 )^2 / ( l1*l2 )
    }
    varB <- sum( l12^2 * varBs * res.df )/(sum( l12 * res.df ))^2
    crit <- qchisq( 1 - alpha, 1 )
    bCI=NA
    if (ci) bCI  <- com.ci( b, varB, crit, z, n, l1, l2, method, lambda, res.df, r.factor, tol=tol)
    list( LR=LR, p=Pvalue, b=b, ci=bCI, varb=varB, lambda=lambda, df=df )
}

elev.com <- function( y, x, groups, method="SMA", alpha=0.05, group.names=sort(unique(groups)) )
{
    x      <- as.matrix( x )
    y      <- as.matrix( y )
    groups <- as.matrix( groups )
    g    <- length( group.names )
    res  <- slope.com( y, x, groups, method=method, ci=FALSE )
    b    <- res$b
    varb <- res$varb
    n      <- matrix( 0, g, 1 )
    varres <- matrix( 0, g, 1 )
    means  <- matrix( 0, g, 2 )
    res    <- y - b*x
    for ( i in 1:g ) {
        iref       <- ( groups==group.names[i] )
        iref       <- iref & ( is.na(x+y) == FALSE )
        n[i]       <- sum( iref )
        means[i,1] <- mean( y[iref] )
        means[i,2] <- mean( x[iref] )
        varres[i]  <- ( var( res[iref] ) )
    }
    varres <- varres *( n - 1 )/( n - 2 )
    as     <- means[,1] - b*means[,2]
    varas  <- diag( array( varres/n ) ) + varb * means[,2]%*%t( means[,2] )
    df     <- g - 1 - sum(n==1)
    L      <- matrix(0,df,g)
    L[,n>1] <- cbind( matrix( 1, df, 1), diag( array( -1, df), nrow=df ) )
    stat   <- t(L%*%as)%*%( solve( L%*%varas%*%t(L) ) )%*%(L%*%as)
    pvalue <- 1 - pchisq( stat, df )
    sinv=matrix(0,g,g)
    sinv[n>1,n>1]   <- solve( varas[n>1,n>1] )
    a      <- (matrix(1,1,g)%*%sinv%*%as)/ sum( sum( sinv) )
    vara   <- 1 / sum( sum( sinv ) )
    crit   <- qchisq( 1 - alpha, 1 )
    crits  <- qt( 1 - alpha/2, n-2 )
    a.ci   <- c( a - sqrt( crit*vara), a + sqrt( crit*vara ) )
    as.ci  <- cbind(as, as - crits*sqrt(diag(varas)), as + crits*sqrt(diag(varas)) )
    list( stat=stat, p=pvalue , a=a, ci=a.ci, as = as.ci, df=df, b=b )
}
